#include "angio/solid/participant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "angio/common/log.hpp"

namespace angio::solid {

SolidRunner::SolidRunner(MPI_Comm comm, SolidScene scene, const std::string& run_dir)
    : comm_(comm), scene_(std::move(scene)) {
  MPI_Comm_rank(comm_, &rank_);
  int size = 1;
  MPI_Comm_size(comm_, &size);
  if (rank_ == 0 && scene_.ranks > 0 && scene_.ranks != size)
    LOG_WARN("solid.ranks is " << scene_.ranks << " but the solver runs on " << size << " MPI ranks");
  model_ = std::make_unique<SolidModel>(comm_, scene_.mesh, scene_.materials, scene_.options);
  for (const auto& p : scene_.pressures) {
    const PressureSpec ps = p;
    model_->add_pressure({p.surface, [ps](double t) { return ps.value * ps.curve.value(t); }});
  }
  for (const auto& s : scene_.springs) model_->add_springs({s.surface, s.stiffness});
  for (const auto& f : scene_.fixed) {
    std::vector<int> nodes;
    for (const auto& face : model_->mesh().surface(f.surface)->faces)
      for (int a = 0; a < face.nn(); ++a) nodes.push_back(face.n[a]);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    for (int c : f.components) model_->add_dirichlet({nodes, c, [](const Vec3d&, double) { return 0.0; }});
  }
  if (scene_.balloon_diameter) {
    const auto& d = *scene_.balloon_diameter;
    const auto& nodes = model_->mesh().node_sets.at(d.node_set);
    auto ring = [&](double target) {
      double best = std::numeric_limits<double>::max();
      std::vector<double> st(nodes.size());  // axial station (arc length on a curved balloon)
      for (size_t i = 0; i < nodes.size(); ++i) st[i] = d.station(model_->mesh().X[nodes[i]]);
      for (double s : st) best = std::min(best, std::abs(s - target));
      std::vector<int> r;
      for (size_t i = 0; i < nodes.size(); ++i)
        if (std::abs(st[i] - target) <= best + 1e-6) r.push_back(nodes[i]);
      return r;
    };
    ring_mid_ = ring(d.s_mid);
    ring_end0_ = ring(d.s_end0);
    ring_end1_ = ring(d.s_end1);
  }
  time_ = scene_.time.start;
  model_->start_at(time_);
  if (!run_dir.empty()) {
    dir_ = run_dir + "/solid";
    writer_ = std::make_unique<FieldWriter>(*model_, dir_);
  }
  record_and_write_(0, time_);
  if (rank_ == 0) {
    LOG_INFO("solid: " << model_->mesh().elements.size() << " elements, " << model_->num_dofs() << " DOFs on "
                       << size << " rank(s); blocks:" << [&] {
                            std::string s;
                            for (const auto& b : model_->mesh().blocks) s += " " + b.name;
                            return s;
                          }());
  }
}

SolidRunner::~SolidRunner() = default;

void reset_reply(const participant::SamplePoints& pts, participant::ContactReply& reply) {
  const size_t n = pts.x.size();
  reply = participant::ContactReply{};
  reply.line_loads.assign(n, {0.0, 0.0, 0.0});
  reply.surface_points = pts.x;
  reply.normals.assign(n, {0.0, 0.0, 0.0});
  reply.penalty.assign(n, 0.0);
  reply.active.assign(n, 0);
}

void SolidRunner::balloon_diameters(double& mid, double& end0, double& end1) const {
  mid = end0 = end1 = 0.0;
  if (!scene_.balloon_diameter) return;
  // Twice the mean distance of a ring's nodes (one material cross-section, nodes evenly spread
  // around) from their centroid: the centroid follows the deformed balloon axis, so a balloon that
  // moves or straightens (curved device, paper §3.2) is not measured from its reference axis.
  auto diam = [&](const std::vector<int>& ring) {
    if (ring.empty()) return 0.0;
    Vec3d c = Vec3d::Zero();
    for (int n : ring) c += model_->position(n);
    c /= double(ring.size());
    double sum = 0.0;
    for (int n : ring) sum += (model_->position(n) - c).norm();
    return 2.0 * sum / double(ring.size());
  };
  mid = diam(ring_mid_);
  end0 = diam(ring_end0_);
  end1 = diam(ring_end1_);
}

void SolidRunner::begin_step(int step, double time) {
  step_ = step;
  time_ = time;
  model_->set_time(time);
}

participant::SolveStats SolidRunner::solve(const participant::SamplePoints& pts, participant::ContactReply& reply) {
  if (stent_contact_) stent_contact_->set_points(pts);
  if (!pts.x.empty() && !stent_contact_ && !warned_contact_ && rank_ == 0) {
    LOG_WARN("solid: no stent contact configured; " << pts.x.size()
                                                     << " beam sample points are ignored (zero line loads)");
    warned_contact_ = true;
  }
  reset_reply(pts, reply);
  last_ = model_->solve();
  if (stent_contact_ && last_.converged) stent_contact_->fill_reply(*model_, reply);
  participant::SolveStats s;
  s.converged = last_.converged;
  s.iterations = last_.iterations;
  s.residual = last_.residual;
  s.residual_history = last_.residual_history;
  if (!last_.converged) {
    std::ostringstream m;
    m << "solid step " << step_ << " t = " << time_ << ": " << last_.message;
    s.message = m.str();
  } else {
    s.message = last_.message;
  }
  return s;
}

void SolidRunner::end_step(bool accept) {
  if (!accept) {
    model_->rollback();
    return;
  }
  model_->commit();
  ++committed_;
  record_and_write_(committed_, time_);
  if (rank_ == 0) {
    const auto& h = history_.back();
    std::ostringstream os;
    os << std::setprecision(4) << "solid step " << committed_ << " t=" << time_;
    for (const auto& [label, p] : h.pressures) os << " " << label << "=" << p << "MPa";
    os << " newton=" << last_.iterations << " |r|=" << std::scientific << std::setprecision(2) << last_.residual;
    if (last_.damping_force > 0.0) os << " |f_damp|=" << last_.damping_force;
    os << std::defaultfloat << std::setprecision(4);
    if (scene_.balloon_diameter) os << " D_mid=" << h.d_mid << " D_ends=" << h.d_end0 << "/" << h.d_end1 << "mm";
    os << " max_p1[";
    for (size_t b = 0; b < h.max_p1.size(); ++b)
      os << (b ? " " : "") << model_->mesh().blocks[b].name << "=" << h.max_p1[b];
    os << "]MPa ksp=" << last_.linear_iterations << std::setprecision(3) << " " << last_.total_seconds
       << "s (assembly " << last_.assembly_seconds << "s, linear " << last_.linear_seconds << "s)";
    LOG_INFO(os.str());
  }
}

void SolidRunner::record_and_write_(int step, double time) {
  std::vector<double> p1;
  std::vector<Vec3d> dir;
  model_->element_stress(p1, dir);
  const size_t nb = model_->mesh().blocks.size();
  std::vector<double> local(nb, -std::numeric_limits<double>::max()), global(nb);
  const auto& le = model_->local_elements();
  for (size_t i = 0; i < le.size(); ++i) {
    const int b = model_->mesh().elements[le[i]].block;
    local[b] = std::max(local[b], p1[i]);
  }
  MPI_Allreduce(local.data(), global.data(), int(nb), MPI_DOUBLE, MPI_MAX, comm_);
  StepSummary s;
  s.step = step;
  s.time = time;
  for (const auto& p : scene_.pressures) s.pressures.emplace_back(p.label, p.value * p.curve.value(time));
  s.max_p1 = global;
  balloon_diameters(s.d_mid, s.d_end0, s.d_end1);
  if (step > 0) {
    s.newton_iterations = last_.iterations;
    s.residual = last_.residual;
    s.solve_seconds = last_.total_seconds;
  }
  history_.push_back(s);
  if (writer_ && (step % scene_.output_every == 0 || step == 0)) writer_->write_step(step, time, p1, dir);
  if (writer_ && rank_ == 0) write_summary_json_();
}

void SolidRunner::write_summary_json_() const {
  std::ostringstream j;
  j << std::setprecision(10);
  j << "{\n  \"units\": {\"length\": \"mm\", \"stress\": \"MPa\", \"time\": \"s\"},\n";
  j << "  \"stress_measure\": \"max over elements of the first principal Cauchy stress of the Gauss-point averaged "
       "element stress\",\n";
  j << "  \"blocks\": [";
  for (size_t b = 0; b < model_->mesh().blocks.size(); ++b)
    j << (b ? ", " : "") << "{\"id\": " << b << ", \"name\": \"" << model_->mesh().blocks[b].name
      << "\", \"part\": \"" << model_->mesh().blocks[b].part << "\"}";
  j << "],\n";
  if (scene_.balloon_diameter) {
    const auto& d = *scene_.balloon_diameter;
    j << "  \"balloon_diameter_stations\": {\"mid\": " << d.s_mid << ", \"end0\": " << d.s_end0
      << ", \"end1\": " << d.s_end1 << ", \"measure\": \"2 x mean distance of the outer-surface node ring from the axis"
      << (d.centerline ? " (the curved centerline of the balloon)" : "") << "\"},\n";
  }
  j << "  \"steps\": [\n";
  for (size_t i = 0; i < history_.size(); ++i) {
    const auto& s = history_[i];
    j << "    {\"step\": " << s.step << ", \"time\": " << s.time;
    for (const auto& [label, p] : s.pressures) j << ", \"" << label << "\": " << p;
    j << ", \"max_principal_stress\": {";
    for (size_t b = 0; b < s.max_p1.size(); ++b)
      j << (b ? ", " : "") << "\"" << model_->mesh().blocks[b].name << "\": " << s.max_p1[b];
    j << "}";
    if (scene_.balloon_diameter) {
      const double dog = s.d_mid > 0 ? (0.5 * (s.d_end0 + s.d_end1) - s.d_mid) / s.d_mid : 0.0;
      j << ", \"balloon_outer_diameter\": {\"mid\": " << s.d_mid << ", \"end0\": " << s.d_end0
        << ", \"end1\": " << s.d_end1 << ", \"dogboning\": " << dog << "}";
    }
    j << ", \"newton_iterations\": " << s.newton_iterations << ", \"residual\": " << s.residual
      << ", \"wall_seconds\": " << s.solve_seconds << "}" << (i + 1 < history_.size() ? "," : "") << "\n";
  }
  j << "  ]\n}\n";
  const std::string tmp = dir_ + "/summary.json.tmp";
  {
    std::ofstream f(tmp);
    f << j.str();
  }
  std::rename(tmp.c_str(), (dir_ + "/summary.json").c_str());
}

void SolidRunner::finish() {
  if (finished_) return;
  finished_ = true;
  if (writer_) writer_->close();
}

// ---------------------------------------------------------------------------------------------
namespace {
enum Cmd : int { kBegin = 1, kSolve = 2, kEnd = 3, kFinish = 4 };

void bcast_points(participant::SamplePoints& p, MPI_Comm comm) {
  long n = long(p.x.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
  p.x.resize(n);
  p.w.resize(n);
  p.radius.resize(n);
  if (n == 0) return;
  MPI_Bcast(p.x.data(), int(3 * n), MPI_DOUBLE, 0, comm);
  MPI_Bcast(p.w.data(), int(n), MPI_DOUBLE, 0, comm);
  MPI_Bcast(p.radius.data(), int(n), MPI_DOUBLE, 0, comm);
}
}  // namespace

void MpiSolidParticipant::begin_step(int step, double time) {
  int cmd = kBegin;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  MPI_Bcast(&step, 1, MPI_INT, 0, comm_);
  MPI_Bcast(&time, 1, MPI_DOUBLE, 0, comm_);
  inner_.begin_step(step, time);
}

participant::SolveStats MpiSolidParticipant::solve(const participant::SamplePoints& pts,
                                                   participant::ContactReply& reply) {
  int cmd = kSolve;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  participant::SamplePoints p = pts;
  if (p.w.size() != p.x.size()) p.w.resize(p.x.size(), 0.0);
  if (p.radius.size() != p.x.size()) p.radius.resize(p.x.size(), 0.0);
  bcast_points(p, comm_);
  return inner_.solve(p, reply);
}

void MpiSolidParticipant::end_step(bool accept) {
  int cmd = kEnd, a = accept ? 1 : 0;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  MPI_Bcast(&a, 1, MPI_INT, 0, comm_);
  inner_.end_step(accept);
}

void MpiSolidParticipant::finish() {
  if (finished_) return;
  finished_ = true;
  int cmd = kFinish;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  inner_.finish();
}

void MpiSolidParticipant::shutdown() { finish(); }

int run_follower(participant::SolidParticipant& inner, MPI_Comm comm) {
  for (;;) {
    int cmd = 0;
    MPI_Bcast(&cmd, 1, MPI_INT, 0, comm);
    switch (cmd) {
      case kBegin: {
        int step;
        double time;
        MPI_Bcast(&step, 1, MPI_INT, 0, comm);
        MPI_Bcast(&time, 1, MPI_DOUBLE, 0, comm);
        inner.begin_step(step, time);
        break;
      }
      case kSolve: {
        participant::SamplePoints p;
        bcast_points(p, comm);
        participant::ContactReply reply;
        inner.solve(p, reply);
        break;
      }
      case kEnd: {
        int a;
        MPI_Bcast(&a, 1, MPI_INT, 0, comm);
        inner.end_step(a != 0);
        break;
      }
      case kFinish: inner.finish(); return 0;
      default: return 1;
    }
  }
}

}  // namespace angio::solid
