#include "angio/solid/contact_scene.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "angio/common/log.hpp"

namespace angio::solid {

namespace {
using scene::Node;

// An entry is a map of options, or `off`/`false` to disable the pair.
bool disabled(const Node& n) {
  if (!n.is_scalar()) return false;
  const std::string v = n.as_string();
  if (v == "off" || v == "false") return true;
  n.fail("a map of options (e.g. {penalty: 10.0}) or 'off'");
}

// `from` (s): the pair is off before this pseudo-time; absent: always on.
double read_from(const Node& n) {
  if (!n.has("from")) return kAlwaysActive;
  return n.get<double>("from");
}

std::optional<double> read_line_pair(const Node& c, const std::string& key, std::optional<double> def, double& from) {
  const auto n = c.optional(key);
  if (!n) return def;
  if (disabled(*n)) return std::nullopt;
  n->check_keys();
  from = read_from(*n);
  return n->get<double>("penalty");
}

// contact.insertion: the virtual insertion tool (insertion_tool.hpp).
ContactSpec::Insertion read_insertion(const Node& n, const Node& root) {
  n.check_keys();
  ContactSpec::Insertion ins;
  const char* what = "'balloon' (its axis from end to end) or a polyline of at least 2 points [[x, y, z], ...] (mm)";
  const Node axis = n.child("axis", what);
  if (axis.is_scalar() && axis.as_string() == "balloon") {
    if (!root.has("balloon")) axis.fail("a polyline (mm): this scene has no balloon");
    ins.balloon_axis = true;
  } else if (!axis.is_sequence() || axis.size() < 2) {
    axis.fail(what);
  }
  for (size_t i = 0; !ins.balloon_axis && i < axis.size(); ++i) {
    const Node p = axis.at(i);
    if (!p.is_sequence() || p.size() != 3) p.fail("a point [x, y, z] (mm)");
    Vec3d x;
    for (int k = 0; k < 3; ++k) {
      x(k) = p.at(k).as_number();
      if (!std::isfinite(x(k))) p.at(k).fail("a finite coordinate (mm)");
    }
    if (!ins.axis.empty() && (x - ins.axis.back()).norm() < 1e-9) p.fail("a point distinct from the one before it");
    ins.axis.push_back(x);
  }
  ins.radius = scene::scaled_curve(n, "radius", scene::load_curves(root));
  const auto [low, peak] = ins.radius.range();
  if (!(peak > 0.0) || low < 0.0 || peak > 50.0)
    n.child("radius").fail("a radius (value x load curve) between 0 and 50 mm, positive somewhere");
  ins.penalty = n.get<double>("penalty");
  return ins;
}
}  // namespace

ContactSpec read_contact_spec(const Node& root) {
  ContactSpec spec;
  const auto c = root.optional("contact");
  if (!c) return spec;
  if (c->is_scalar() && disabled(*c)) {
    spec.stent_balloon.reset();
    spec.stent_artery.reset();
    spec.balloon_artery.reset();
    return spec;
  }
  c->check_keys();
  spec.search_radius = c->get<double>("search_radius");
  spec.line_regularization = c->get<double>("line_regularization");
  if (!(spec.line_regularization < 0.5 * spec.search_radius))
    c->child("line_regularization").fail("a value below half of contact.search_radius (mm)");
  spec.line_averaged_normals = c->get<std::string>("line_normals") == "averaged";
  const LineTangentFlags line_tangent = line_tangent_flags(c->get<std::string>("line_tangent"));
  spec.line_ring_tangent = line_tangent.ring;
  spec.line_force_tangent = line_tangent.force;
  spec.line_definite_force_terms = line_tangent.definite;
  spec.log = c->get<bool>("log");
  spec.stent_balloon = read_line_pair(*c, "stent_balloon", spec.stent_balloon, spec.stent_balloon_from);
  spec.stent_artery = read_line_pair(*c, "stent_artery", spec.stent_artery, spec.stent_artery_from);
  if (const auto n = c->optional("insertion")) {
    if (!root.has("artery") && !root.has("patient"))
      n->fail("no insertion tool without an artery (it opens the lumen)");
    spec.insertion = read_insertion(*n, root);
  }
  if (const auto n = c->optional("balloon_artery")) {
    if (disabled(*n)) {
      spec.balloon_artery.reset();
    } else {
      n->check_keys();
      auto& o = *spec.balloon_artery;
      o.from = read_from(*n);
      o.penalty = n->get<double>("penalty");
      o.quadrature = n->get<int>("quadrature");
      o.two_pass = n->get<bool>("two_pass");
      o.regularization = n->get<double>("regularization");
      // The side whose Gauss points are projected: seen from the balloon, the lumen is a concave
      // faceted surface, and the closest face (and with it the contact normal) jumps at the bisector
      // of two faces; seen from the lumen, the balloon is convex and the closest point moves
      // continuously over its edges.
      if (n->get<std::string>("slave") == "artery") std::swap(o.slave, o.master);
      if (!(o.regularization < 0.5 * spec.search_radius))
        n->child("regularization").fail("a value below half of contact.search_radius (mm)");
    }
  }
  if (spec.balloon_artery) spec.balloon_artery->search_radius = spec.search_radius;
  return spec;
}

ContactSetup::ContactSetup(SolidRunner& runner, const ContactSpec& spec) : runner_(runner) {
  const SolidModel& model = runner.model();
  const Mesh& mesh = model.mesh();
  const bool has_balloon = mesh.surface("balloon_outer") != nullptr;
  const bool has_artery = mesh.surface("artery_inner") != nullptr;
  PenaltyStentContact::Options so;
  so.search_radius = spec.search_radius;
  so.regularization = spec.line_regularization;
  so.averaged_normals = spec.line_averaged_normals;
  so.ring_tangent = spec.line_ring_tangent;
  so.force_tangent = spec.line_force_tangent;
  so.definite_force_terms = spec.line_definite_force_terms;
  if (has_balloon) so.balloon_penalty = spec.stent_balloon;
  if (has_artery) so.artery_penalty = spec.stent_artery;
  so.balloon_from = spec.stent_balloon_from;
  so.artery_from = spec.stent_artery_from;
  if (so.balloon_penalty || so.artery_penalty) {
    stent_ = std::make_unique<PenaltyStentContact>(model, so);
    composite_.set_stent(stent_.get());
  }
  if (spec.balloon_artery && has_balloon && has_artery) {
    balloon_artery_ = std::make_unique<PenaltySurfaceContact>(model, *spec.balloon_artery);
    composite_.add_model(balloon_artery_.get());
  }
  if (spec.insertion && has_artery) {
    InsertionTool::Options io;
    io.axis = spec.insertion->balloon_axis ? runner.scene().balloon_spine : spec.insertion->axis;
    if (io.axis.size() < 2)
      throw std::runtime_error("contact.insertion.axis: balloon: the balloon has no axis (a mesh file without one?)");
    io.radius = [r = spec.insertion->radius](double t) { return r.at(t); };
    io.penalty = spec.insertion->penalty;
    insertion_ = std::make_unique<InsertionTool>(model, io);
    composite_.add_model(insertion_.get());
  }
  const bool log = spec.log;
  composite_.after_reply = [this, log](const SolidModel& m, const participant::ContactReply& reply) {
    if (!log || m.rank() != 0) return;
    // the solve's own split (SolveReport): contact add() inside its assemblies only
    const double dt_contact = runner_.last_report().contact_seconds;
    const double dt_solve = runner_.last_report().total_seconds;
    std::ostringstream os;
    os << std::setprecision(4) << "contact t=" << m.time();
    if (stent_ && stent_->num_points() > 0)
      os << " stent: " << reply.n_active << "/" << stent_->num_points() << " points active, min gap " << reply.min_gap
         << " mm, |sum w q| "
         << std::sqrt(reply.total_force[0] * reply.total_force[0] + reply.total_force[1] * reply.total_force[1] +
                      reply.total_force[2] * reply.total_force[2])
         << " N;";
    if (balloon_artery_) {
      const auto& s = balloon_artery_->last();
      os << " balloon-artery: " << s.num_active << "/" << s.num_points << " Gauss points active, min gap " << s.min_gap
         << " mm, sum|f| " << s.force_magnitude << " N, area " << balloon_artery_->active_area() << " mm^2;";
    }
    if (insertion_) {
      const auto& s = insertion_->last();
      os << " insertion: R " << insertion_->radius(m.time()) << " mm, " << s.num_active
         << " nodes pushed, largest penetration " << -s.min_gap << " mm, sum|f| " << s.force_magnitude << " N;";
    }
    os << " contact time " << dt_contact << " s of " << dt_solve << " s solve";
    if (dt_solve > 0) os << " (" << std::setprecision(3) << 100.0 * dt_contact / dt_solve << " %)";
    LOG_INFO(os.str());
  };
  runner.set_stent_contact(&composite_);
  // forces on the endothelium per contact, in the runner's summary
  if (stent_) runner.add_contact_report("stent", stent_.get());
  if (balloon_artery_) runner.add_contact_report("balloon", balloon_artery_.get());
  if (insertion_) runner.add_contact_report("insertion", insertion_.get());
}

ContactSetup::~ContactSetup() {
  runner_.set_stent_contact(nullptr);
  runner_.clear_contact_reports();
}

std::unique_ptr<ContactSetup> make_contact(const Node& root, SolidRunner& runner) {
  return std::make_unique<ContactSetup>(runner, read_contact_spec(root));
}

}  // namespace angio::solid
