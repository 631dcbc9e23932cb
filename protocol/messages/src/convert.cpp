#include "angio/messages/convert.hpp"

namespace angio::msg {

std::vector<participant::Vec3> to_vec3s(const flatbuffers::Vector<const fb::Vec3*>* v) {
  std::vector<participant::Vec3> out;
  if (!v) return out;
  out.reserve(v->size());
  for (const fb::Vec3* p : *v) out.push_back({p->x(), p->y(), p->z()});
  return out;
}

std::vector<double> to_doubles(const flatbuffers::Vector<double>* v) {
  return v ? std::vector<double>(v->begin(), v->end()) : std::vector<double>{};
}

participant::SamplePoints to_sample_points(const fb::SamplePoints* p) {
  participant::SamplePoints out;
  if (!p) return out;
  out.x = to_vec3s(p->x());
  out.w = to_doubles(p->w());
  out.radius = to_doubles(p->radius());
  if (out.w.size() != out.x.size() || out.radius.size() != out.x.size())
    throw ProtocolError("sample points disagree in length: " + std::to_string(out.x.size()) + " positions, " +
                        std::to_string(out.w.size()) + " weights, " + std::to_string(out.radius.size()) + " radii");
  return out;
}

participant::SolveStats to_stats(const fb::SolveStats* s) {
  participant::SolveStats out;
  if (!s) throw ProtocolError("solve reply without statistics");
  out.converged = s->converged();
  out.iterations = static_cast<int>(s->iterations());
  out.residual = s->residual();
  out.residual_history = to_doubles(s->residual_history());
  out.message = s->message() ? s->message()->str() : "";
  return out;
}

participant::ContactReply to_contact(const fb::SolidSolveReply& r) {
  participant::ContactReply c;
  c.line_loads = to_vec3s(r.line_loads());
  c.surface_points = to_vec3s(r.surface_points());
  c.regularization = r.regularization();
  c.normals = to_vec3s(r.normals());
  c.penalty = to_doubles(r.penalty());
  if (r.active()) c.active.assign(r.active()->begin(), r.active()->end());
  if (const auto* d = r.contact()) {
    c.n_active = static_cast<int>(d->n_active());
    c.min_gap = d->min_gap();
    if (d->total_force()) c.total_force = {d->total_force()->x(), d->total_force()->y(), d->total_force()->z()};
  }
  return c;
}

}  // namespace angio::msg
