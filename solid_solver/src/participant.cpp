#include "angio/solid/participant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include <sys/resource.h>

#include <nlohmann/json.hpp>
#include <petsclog.h>

#include "angio/common/log.hpp"
#include "angio/solid/gather.hpp"
#include "petsc_check.hpp"

namespace angio::solid {

SolidRunner::SolidRunner(MPI_Comm comm, SolidScene scene, const std::string& run_dir)
    : comm_(comm), scene_(std::move(scene)) {
  MPI_Comm_rank(comm_, &rank_);
  int size = 1;
  MPI_Comm_size(comm_, &size);
  if (rank_ == 0 && scene_.ranks > 0 && scene_.ranks != size)
    LOG_WARN("solid.ranks is " << scene_.ranks << " but the solver runs on " << size << " MPI ranks");
  // the model owns the mesh (model().mesh()): a copy kept in the scene would hold the whole mesh
  // twice on every rank
  model_ = std::make_unique<SolidModel>(comm_, std::move(scene_.mesh), scene_.materials, scene_.options);
  scene_.mesh = Mesh{};
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
  if (scene_.lumen) {
    const auto& mesh = model_->mesh();
    const SurfaceSet* endo = mesh.surface(scene_.lumen->node_set);
    std::vector<int> nodes;
    for (const auto& f : endo->faces)
      for (int a = 0; a < f.nn(); ++a) nodes.push_back(f.n[a]);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    std::vector<double> st(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) st[i] = scene_.lumen->station(mesh.X[nodes[i]]);
    lumen_ = LumenProfile(st, scene_.lumen_max_stations);
    const std::vector<double> area = nodal_areas(mesh, *endo);  // by mesh node
    const int n0 = model_->owned_node_begin();
    endothelium_area_.resize(model_->owned_node_end() - n0);
    for (std::size_t i = 0; i < endothelium_area_.size(); ++i)
      endothelium_area_[i] = area[model_->old_index(n0 + int(i))];
    lumen_nodes_ = std::move(nodes);
  }
  // what the per-step measures read on every rank: the balloon's rings and the lumen
  std::vector<int> measured = lumen_nodes_;
  for (const auto* r : {&ring_mid_, &ring_end0_, &ring_end1_}) measured.insert(measured.end(), r->begin(), r->end());
  model_->hold_nodes(measured);
  recovery_ = std::make_unique<StressRecovery>(*model_);
  nodal_stress_names_ = nodal_stress_field_names(model_->mesh());
  time_ = scene_.time.start;
  ok_time_ = committed_ok_time_ = time_;
  model_->start_at(time_);
  if (scene_.initial_state) {  // continue from an earlier run's committed state (time.start is its time)
    apply_state(*model_, *scene_.initial_state, scene_.initial_parts);
    if (rank_ == 0) {
      std::string parts;
      for (const auto& p : scene_.initial_parts) parts += " " + p;
      LOG_INFO("solid: continuing from " << scene_.initial_state->path << " at t = " << time_ << " s, parts:" << parts);
    }
    scene_.initial_state.reset();  // its copy of the parts is not needed any more
  }
  if (!run_dir.empty()) {
    dir_ = run_dir + "/solid";
    writer_ = std::make_unique<FieldWriter>(*model_, dir_);
  }
  record_and_write_(0, time_);
  if (rank_ == 0) {
    LOG_INFO("solid: " << model_->mesh().elements.size() << " elements, " << model_->num_dofs() << " DOFs on " << size
                       << " rank(s); blocks:" << [&] {
                            std::string s;
                            for (const auto& b : model_->mesh().blocks) s += " " + b.name;
                            return s;
                          }());
    const double atol = scene_.options.newton.atol, F = scene_.peak_load_norm;
    if (F > 0.0)  // no pressure load (a scene loaded by displacements only): nothing to judge atol by
      LOG_INFO("solid: peak pressure load " << F << " N (reference mesh), Newton atol " << atol << " N = " << atol / F
                                            << " of it");
    if (F > 0.0 && atol > kWarnAtolOfLoad * F)
      LOG_WARN("solid.newton.atol = " << atol << " N is more than " << kWarnAtolOfLoad << " of the peak pressure load ("
                                      << scene_.peak_load_norm
                                      << " N): the equilibrium error it accepts may show in the results");
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

namespace {
// The process's peak resident set so far (getrusage, KiB on Linux).
long peak_resident_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}
}  // namespace

void SolidRunner::begin_step(int step, double time) {
  step_ = step;
  time_ = time;
  model_->set_time(time);
  predicted_ = model_->predict();
  linearizable_ = false;  // no solve of this step yet
}

participant::SolveStats SolidRunner::solve(const participant::SamplePoints& pts, participant::ContactReply& reply,
                                           double tolerance) {
  if (stent_contact_) stent_contact_->set_points(pts);
  points_ = pts;
  if (!pts.x.empty() && !stent_contact_ && !warned_contact_ && rank_ == 0) {
    LOG_WARN("solid: no stent contact configured; " << pts.x.size()
                                                    << " beam sample points are ignored (zero line loads)");
    warned_contact_ = true;
  }
  reset_reply(pts, reply);
  if (setup_peak_kib_ < 0) setup_peak_kib_ = peak_resident_kib();
  const bool continuation = scene_.options.newton.continuation > 1;
  const std::vector<double> u_start = !continuation ? std::vector<double>{}
                                      : predicted_  ? model_->committed_state()
                                                    : model_->state();
  last_ = model_->solve(tolerance);
  totals_.add(last_);
  if (!last_.converged && continuation) last_ = continuation_(pts, u_start, tolerance);
  if (last_.converged) {
    ok_time_ = time_;
    ok_x_ = pts.x;
    predicted_ = false;
  }
  if (stent_contact_ && last_.converged) {
    const double t_reply = MPI_Wtime();
    stent_contact_->fill_reply(*model_, reply);
    reply_seconds_ += MPI_Wtime() - t_reply;
  }
  // the state a linearized response starts from (linear_response): this reply, and the contact
  // forces here once a response asks for them
  linearizable_ = last_.converged;
  linear_forces_.clear();
  if (linearizable_) linear_reply_ = reply;
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

participant::SolveStats SolidRunner::linear_response(const std::vector<participant::Vec3>& dx,
                                                     std::vector<double>& plane_shift,
                                                     std::vector<participant::Vec3>& normal_turn) {
  participant::SolveStats out;
  plane_shift.clear();
  normal_turn.clear();
  StentContact* line = stent_contact_ ? stent_contact_->line_part() : nullptr;
  if (!line || dx.size() != points_.size() || points_.x.empty() || !linearizable_) {
    out.message = "a linearized response needs a converged solve of this step with the stent's " +
                  std::to_string(points_.size()) + " sample points before it (got " + std::to_string(dx.size()) +
                  " displacements" + (line ? ")" : ", and this solid has no stent contact)");
    return out;
  }
  double dmax = 0.0;
  for (const auto& d : dx) dmax = std::max({dmax, std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
  // Forward differences of the contact forces in the points and of the planes in the points and the
  // displacement together, from the solve's own reply and the forces there (computed once for all
  // products at this state): exact for the linear penalty law away from its switches, O(h) in the
  // surface's curvature; 1e-6 mm against positions of order 1 mm leaves round-off of about 1e-10
  // relative.
  const double h = dmax > 0.0 ? 1e-6 / dmax : 0.0;
  std::string failed;
  participant::ContactReply shifted;
  const double t_product = MPI_Wtime();
  if (h > 0.0) {
    if (linear_forces_.empty()) linear_forces_ = model_->contact_forces(*line);
    participant::SamplePoints moved = points_;
    for (std::size_t i = 0; i < moved.x.size(); ++i)
      for (int c = 0; c < 3; ++c) moved.x[i][c] += h * dx[i][c];
    line->set_points(moved);
    std::vector<Vec3d> f = model_->contact_forces(*line);
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = (f[i] - linear_forces_[i]) / h;  // on the solid: K du = df
    std::vector<double> du;
    const double t_linear = MPI_Wtime();
    failed = model_->tangent_response(f, du);
    product_linear_seconds_ += MPI_Wtime() - t_linear;
    if (failed.empty()) {
      const std::vector<double> u0 = model_->state();
      std::vector<double> u1 = u0;
      for (std::size_t i = 0; i < u1.size(); ++i) u1[i] += h * du[i];
      model_->restore_state(u1);
      reset_reply(moved, shifted);
      line->fill_reply(*model_, shifted);
      model_->restore_state(u0);
    }
    line->set_points(points_);
  }
  product_seconds_ += MPI_Wtime() - t_product;
  ++products_;
  if (!failed.empty()) {
    out.message = "solid linearized response at step " + std::to_string(step_) + ": " + failed;
    return out;
  }
  out.converged = true;
  if (rank_ != 0) return out;
  const participant::ContactReply& base = linear_reply_;
  plane_shift.assign(base.penalty.size(), 0.0);
  normal_turn.assign(base.penalty.size(), {0.0, 0.0, 0.0});
  if (h > 0.0)
    for (std::size_t j = 0; j < plane_shift.size(); ++j) {
      if (!(base.penalty[j] > 0.0) || !(shifted.penalty[j] > 0.0)) continue;  // a plane in range at both ends
      const auto& n = base.normals[j];
      double d = 0.0;
      for (int c = 0; c < 3; ++c) d += n[c] * (shifted.surface_points[j][c] - base.surface_points[j][c]);
      plane_shift[j] = d / h;
      for (int c = 0; c < 3; ++c) normal_turn[j][c] = (shifted.normals[j][c] - n[c]) / h;
    }
  return out;
}

SolveReport SolidRunner::continuation_(const participant::SamplePoints& pts, const std::vector<double>& u_start,
                                       double tolerance) {
  const SolveReport failed = last_;
  // From the last converged state: sample points of a different count (the first solve of a run)
  // are not interpolated, the pseudo-time still is.
  const bool move_points = ok_x_.size() == pts.x.size();
  participant::SamplePoints sub = pts;
  auto set_stage = [&](double lambda) {
    model_->set_time(ok_time_ + lambda * (time_ - ok_time_));
    if (move_points)
      for (size_t i = 0; i < pts.x.size(); ++i)
        for (int c = 0; c < 3; ++c) sub.x[i][c] = ok_x_[i][c] + lambda * (pts.x[i][c] - ok_x_[i][c]);
    if (stent_contact_) stent_contact_->set_points(sub);
  };
  model_->restore_state(u_start);
  const double h_min = 1.0 / scene_.options.newton.continuation;
  double lambda = 0.0, h = 0.5;
  int stages = 0, halvings = 0;
  SolveReport rep;
  std::vector<double> u_stage;
  while (lambda < 1.0) {
    const double next = std::min(1.0, lambda + h);
    set_stage(next);
    u_stage = model_->state();
    rep = model_->solve(tolerance);
    totals_.add(rep);
    if (rep.converged) {
      lambda = next;
      ++stages;
      h = std::min(2.0 * h, 0.5);
      continue;
    }
    model_->restore_state(u_stage);
    h *= 0.5;
    ++halvings;
    if (h < h_min * (1.0 - 1e-12)) break;
  }
  set_stage(1.0);  // the solve's own time and points, whatever happened
  if (lambda >= 1.0) {
    if (rank_ == 0)
      LOG_INFO("solid step " << step_ << " t = " << time_ << ": Newton failed (" << failed.message << "); continued in "
                             << stages << " sub-increments (" << halvings << " halvings)");
    return rep;
  }
  SolveReport out = failed;
  std::ostringstream m;
  m << failed.message << "; continuation stopped at " << lambda << " of the increment (sub-increment below 1/"
    << scene_.options.newton.continuation << ": " << rep.message << ")";
  out.message = m.str();
  return out;
}

void SolidRunner::end_step(bool accept) {
  linearizable_ = false;
  if (!accept) {
    model_->rollback();
    ok_time_ = committed_ok_time_;
    ok_x_ = committed_ok_x_;
    return;
  }
  committed_ok_time_ = ok_time_;
  committed_ok_x_ = ok_x_;
  model_->commit();
  ++committed_;
  record_and_write_(committed_, time_);
  if (committed_ % scene_.output.every == 0) write_state_();
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
    os << "]MPa ksp=" << last_.linear_iterations << " pc_setups=" << last_.factorizations << std::setprecision(3) << " "
       << last_.total_seconds << "s (assembly " << last_.assembly_seconds << "s, linear " << last_.linear_seconds
       << "s)";
    LOG_INFO(os.str());
  }
}

void SolidRunner::block_stress_(const std::vector<double>& p1, const std::vector<double>& vol, StepSummary& s) const {
  const std::vector<ElementStressSummary> e =
      element_stress_summary(comm_, *model_, p1, vol, scene_.stress_average_radius);
  s.stress.assign(e.size(), BlockStress{});
  for (size_t b = 0; b < e.size(); ++b) static_cast<ElementStressSummary&>(s.stress[b]) = e[b];
}

void SolidRunner::nodal_stress_(StepSummary& s) const {
  // every owned (node, block) of the recovery as (block, p1, weight, on the lumen, current x y z),
  // gathered on rank 0 (as the element values in block_stress_)
  const StressRecovery& rec = *recovery_;
  const int nb = rec.num_blocks(), n0 = model_->owned_node_begin();
  std::vector<double> mine;
  for (int i = 0; i < rec.num_owned(); ++i) {
    const int node = model_->old_index(n0 + i);
    const double lumen = !endothelium_area_.empty() && endothelium_area_[i] > 0.0 ? 1.0 : 0.0;
    const Vec3d x = model_->position(node);
    for (int b = 0; b < nb; ++b)
      if (rec.has(i, b)) mine.insert(mine.end(), {double(b), rec.p1(i, b), rec.weight(i, b), lumen, x(0), x(1), x(2)});
  }
  const std::vector<double> all = gather_on_root(comm_, mine);
  if (rank_ != 0) return;
  std::vector<std::vector<double>> values(nb), weights(nb);
  for (size_t k = 0; k + 6 < all.size(); k += 7) {
    const int b = int(all[k]);
    const double v = all[k + 1];
    BlockStress& bs = s.stress[b];
    values[b].push_back(v);
    weights[b].push_back(all[k + 2]);
    if (!(v <= bs.max_nodal)) {  // also the first (max_nodal NaN)
      bs.max_nodal = v;
      bs.where_nodal = Vec3d(all[k + 4], all[k + 5], all[k + 6]);
    }
    if (all[k + 3] > 0.0 && !(v <= bs.max_endothelium_nodal)) bs.max_endothelium_nodal = v;
  }
  for (int b = 0; b < nb; ++b)
    if (!values[b].empty()) s.stress[b].p99_nodal = weighted_quantile(values[b], weights[b], 0.99);
}

void SolidRunner::artery_measures_(StepSummary& s, std::vector<double>& contact_pressure) {
  const auto& mesh = model_->mesh();
  // maximum displacement per part (the prestressed state: paper 0.14 mm), over each rank's elements,
  // reported in the order of the parts' names
  std::vector<std::string> parts = part_names(mesh);
  std::sort(parts.begin(), parts.end());
  std::vector<std::size_t> part_of(mesh.blocks.size());
  for (std::size_t b = 0; b < part_of.size(); ++b)
    part_of[b] = std::size_t(std::find(parts.begin(), parts.end(), mesh.blocks[b].part) - parts.begin());
  std::vector<double> umax(parts.size(), 0.0), all(parts.size(), 0.0);
  for (int e : model_->local_elements()) {
    const auto& el = mesh.elements[e];
    for (int a = 0; a < el.nn(); ++a)
      umax[part_of[el.block]] = std::max(umax[part_of[el.block]], model_->displacement(el.n[a]).norm());
  }
  MPI_Allreduce(umax.data(), all.data(), int(parts.size()), MPI_DOUBLE, MPI_MAX, comm_);
  for (std::size_t k = 0; k < parts.size(); ++k) s.max_displacement.emplace_back(parts[k], all[k]);
  if (lumen_.empty()) return;
  std::vector<Vec3d> x(lumen_nodes_.size());  // held on every rank: the lumen's diameters read these
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = model_->position(lumen_nodes_[i]);
  s.lumen_diameter = lumen_.diameters(x, &s.lumen_centroid);
  if (!points_.x.empty()) {  // where the stent sits, in the station coordinate of the lumen profile
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : points_.x) {
      const double st = scene_.lumen->station(Vec3d(p[0], p[1], p[2]));
      lo = std::min(lo, st);
      hi = std::max(hi, st);
    }
    s.stent_stations = std::make_pair(lo, hi);
  }
  // contact on the endothelium: force per contact model (summed over each rank's owned nodes), and
  // the pressure field of all of them at the owned nodes
  const std::size_t owned = endothelium_area_.size();
  contact_pressure.assign(owned, 0.0);
  std::vector<Vec3d> total(owned, Vec3d::Zero());
  std::vector<double> force(contact_reports_.size(), 0.0);  // this rank's share, then the sum
  for (size_t k = 0; k < contact_reports_.size(); ++k) {
    const std::vector<Vec3d> f = model_->contact_forces(*contact_reports_[k].second);
    for (size_t i = 0; i < owned; ++i)
      if (endothelium_area_[i] > 0.0) {
        force[k] += f[i].norm();
        total[i] += f[i];
      }
  }
  MPI_Allreduce(MPI_IN_PLACE, force.data(), int(force.size()), MPI_DOUBLE, MPI_SUM, comm_);
  for (size_t k = 0; k < contact_reports_.size(); ++k)
    s.artery_contact_force.emplace_back(contact_reports_[k].first, force[k]);
  for (size_t i = 0; i < owned; ++i)
    if (endothelium_area_[i] > 0.0) contact_pressure[i] = total[i].norm() / endothelium_area_[i];
  if (stent_contact_) {
    std::vector<double> gap, weight;
    const double t_gaps = MPI_Wtime();
    stent_contact_->gaps(*model_, scene_.lumen->node_set, gap, weight);
    reply_seconds_ += MPI_Wtime() - t_gaps;
    if (!gap.empty()) {
      s.apposition = apposition(gap, weight, scene_.apposition_threshold);
      if (rank_ == 0 && writer_) write_apposition_csv_(gap, weight);
    }
  }
}

void SolidRunner::write_apposition_csv_(const std::vector<double>& gap, const std::vector<double>& weight) const {
  // the last committed step only: one row per strut sample point
  const std::string tmp = dir_ + "/apposition.csv.tmp";
  {
    std::ofstream f(tmp);
    f << "# stent apposition at t = " << time_ << " s: gap = distance from the strut surface to the endothelium (mm; "
      << "negative: embedded; inf: no wall within the contact search radius), weight = arc length (mm); "
      << "malapposed if gap > " << scene_.apposition_threshold << " mm\n";
    f << "point,weight,gap,malapposed\n" << std::setprecision(10);
    for (size_t i = 0; i < gap.size(); ++i)
      f << i << "," << weight[i] << "," << gap[i] << "," << (gap[i] <= scene_.apposition_threshold ? 0 : 1) << "\n";
  }
  std::rename(tmp.c_str(), (dir_ + "/apposition.csv").c_str());
}

void SolidRunner::record_and_write_(int step, double time) {
  std::vector<double> p1, vol;
  std::vector<Vec3d> dir;
  std::vector<Mat3> gauss;
  model_->element_stress(p1, dir, &vol, &gauss);
  StepSummary s;
  s.step = step;
  s.time = time;
  for (const auto& p : scene_.pressures) s.pressures.emplace_back(p.label, p.value * p.curve.value(time));
  const double t_summary = MPI_Wtime();
  block_stress_(p1, vol, s);
  stress_summary_seconds_ += MPI_Wtime() - t_summary;
  const bool recovered = recovery_->recover(gauss);
  recovery_seconds_ += recovery_->last_seconds();
  if (!recovered && rank_ == 0 && !warned_recovery_) {
    LOG_WARN("solid: the nodal stress recovery (CG on the mass matrix) did not converge at step "
             << step << "; its values are those of the last iterate");
    warned_recovery_ = true;
  }
  nodal_stress_(s);
  // the maxima on every rank (the log line and the history of the followers)
  const size_t nb = model_->mesh().blocks.size();
  std::vector<double> local(nb, -std::numeric_limits<double>::max());
  const auto& le = model_->local_elements();
  for (size_t i = 0; i < le.size(); ++i) {
    const int b = model_->mesh().elements[le[i]].block;
    local[b] = std::max(local[b], p1[i]);
  }
  s.max_p1.resize(nb);
  MPI_Allreduce(local.data(), s.max_p1.data(), int(nb), MPI_DOUBLE, MPI_MAX, comm_);
  std::vector<double> contact_pressure;
  artery_measures_(s, contact_pressure);
  balloon_diameters(s.d_mid, s.d_end0, s.d_end1);
  if (step > 0) {
    s.newton_iterations = last_.iterations;
    s.residual = last_.residual;
    s.solve_seconds = last_.total_seconds;
  }
  history_.push_back(s);
  // the first and the last step always (a run continued from it, e.g. the next phase of a procedure,
  // starts where the fields end)
  const bool last = time >= scene_.time.end - 1e-12 * std::max(1.0, std::abs(scene_.time.end));
  if (writer_ && (step % scene_.output.every == 0 || step == 0 || last)) {
    std::vector<std::pair<std::string, const std::vector<double>*>> nodal;  // at the owned nodes
    // at every rank's owned nodes where artery_measures_ computed it (lumen_ is the same on all ranks)
    if (!lumen_.empty()) nodal.emplace_back("contact_pressure", &contact_pressure);
    std::vector<std::vector<double>> fields(recovery_->num_blocks());
    for (int b = 0; b < recovery_->num_blocks(); ++b) {
      fields[b] = recovery_->p1_field(b);
      nodal.emplace_back(nodal_stress_names_[b], &fields[b]);
    }
    writer_->write_step(step, time, p1, dir, nodal);
  }
  write_summary_();
}

namespace {
constexpr int kPerRank = 5;  // the figures per rank of write_summary_()
}  // namespace

void SolidRunner::write_summary_() {
  if (!writer_) return;
  // Per rank, gathered on rank 0 for summary.json: the peak resident set (getrusage, KiB on Linux)
  // and PETSc's own message counters (its vector scatters and matrix assembly, not MUMPS' traffic),
  // summed as -log_view sums them (each message counted once, half of sends plus receives): the
  // memory and messages per rank of a scaling study from every run, not from a separate profile
  // (docs/performance.md, "Solid memory and messages per rank"). One gather per commit.
  // The peak before the first solve splits what the setup holds (the mesh every rank reads, the model,
  // the matrix's pattern, the contact's structures) from what the solves add (the factorizations).
  // And the nodes whose displacement each rank holds (SolidModel::hold_nodes).
  const double mine[kPerRank] = {
      double(peak_resident_kib()), 0.5 * (petsc_irecv_ct + petsc_isend_ct + petsc_recv_ct + petsc_send_ct),
      0.5 * (petsc_irecv_len + petsc_isend_len + petsc_recv_len + petsc_send_len),
      double(setup_peak_kib_ < 0 ? peak_resident_kib() : setup_peak_kib_), double(model_->num_held_nodes())};
  int size = 1;
  MPI_Comm_size(comm_, &size);
  std::vector<double> per_rank(rank_ == 0 ? kPerRank * size : 0);
  MPI_Gather(mine, kPerRank, MPI_DOUBLE, per_rank.data(), kPerRank, MPI_DOUBLE, 0, comm_);
  // the matrix's allocated entries (its pattern, contact couplings included): what every
  // factorization's fill starts from
  MatInfo info{};
  ANGIO_PETSC(MatGetInfo(model_->matrix(), MAT_GLOBAL_SUM, &info));
  if (rank_ == 0) write_summary_json_(per_rank, info.nz_allocated);
}

void SolidRunner::write_summary_json_(const std::vector<double>& per_rank, double matrix_nonzeros) const {
  using nlohmann::ordered_json;
  const auto& mesh = model_->mesh();
  auto finite = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr); };
  ordered_json j;
  j["units"] = {{"length", "mm"}, {"stress", "MPa"}, {"force", "N"}, {"time", "s"}};
  j["stress_measure"] =
      "first principal Cauchy stress of the Gauss-point averaged element stress: max over the elements of a block "
      "(with the current centroid of that element) and the 99th percentile by reference volume";
  j["stress_average_radius"] = scene_.stress_average_radius;
  j["stress_measure_averaged"] =
      "first principal Cauchy stress of the elements (as stress_measure) averaged over a ball of radius "
      "stress_average_radius (mm) within the block, sampled at the block's Gauss points in the current configuration "
      "(each with its element's value and its share of the element's reference volume); per block the max over balls "
      "centred at its element centroids and nodes (with that centre): converges under refinement where the element "
      "max and p99 at a strut do not (docs/validation.md, mesh ladder)";
  j["stress_measure_nodal"] =
      "first principal Cauchy stress of the recovered nodal tensor: L2 projection (consistent mass, reference "
      "configuration) of the Gauss-point Cauchy tensor onto the nodes of each block separately, so a node on a layer "
      "interface has one value per layer (solid.h5 fields stress_p1_nodal_<block>); per block the max over its nodes "
      "(with the current position of that node), the 99th percentile (nodes weighted by their share V_e/n_e of the "
      "block's reference volume) and the max over its nodes on the lumen surface (endothelium; blocks that touch it)";
  j["blocks"] = ordered_json::array();
  for (size_t b = 0; b < mesh.blocks.size(); ++b)
    j["blocks"].push_back({{"id", b}, {"name", mesh.blocks[b].name}, {"part", mesh.blocks[b].part}});
  if (scene_.balloon_diameter) {
    const auto& d = *scene_.balloon_diameter;
    j["balloon_diameter_stations"] = {
        {"mid", d.s_mid},
        {"end0", d.s_end0},
        {"end1", d.s_end1},
        {"measure", std::string("2 x mean distance of the outer-surface node ring from the axis") +
                        (d.centerline ? " (the curved centerline of the balloon)" : "")}};
  }
  if (!lumen_.empty()) {
    j["lumen_stations"] = lumen_.stations();
    j["lumen_measure"] =
        "lumen diameter per station along the reference vessel axis: 2 x mean distance of the endothelium nodes of the "
        "station from their centroid; lumen_centroid: that centroid (x, y, z), the deformed lumen centerline";
    j["artery_contact_force_measure"] = "sum over the endothelium nodes of |nodal contact force| (N), per contact";
    j["apposition_threshold"] = scene_.apposition_threshold;
  }
  {  // every solve so far (rejected steps and coupling iterations included), seconds on rank 0
    const auto& t = totals_;
    int ranks = 1;
    MPI_Comm_size(comm_, &ranks);
    std::vector<double> peak_mib, messages, message_mib, setup_mib, held;
    for (size_t r = 0; r + kPerRank <= per_rank.size(); r += kPerRank) {
      peak_mib.push_back(per_rank[r] / 1024.0);
      messages.push_back(per_rank[r + 1]);
      message_mib.push_back(per_rank[r + 2] / (1024.0 * 1024.0));
      setup_mib.push_back(per_rank[r + 3] / 1024.0);
      held.push_back(per_rank[r + 4]);
    }
    j["timing"] = {{"ranks", ranks},
                   {"dofs", model_->num_dofs()},
                   {"solves", t.solves},
                   {"newton_iterations", t.newton_iterations},
                   {"tangent_assemblies", t.tangent_assemblies},
                   {"factorizations", t.factorizations},
                   {"matrix_pattern_rebuilds", model_->pattern_rebuilds()},
                   {"matrix_nonzeros", matrix_nonzeros},
                   {"linear_iterations", t.linear_iterations},
                   {"assembly_seconds", t.assembly_seconds},
                   {"contact_seconds", t.contact_seconds},
                   {"contact_reply_seconds", reply_seconds_},
                   {"interface_products", products_},
                   {"interface_product_seconds", product_seconds_},
                   {"interface_product_linear_seconds", product_linear_seconds_},
                   {"linear_seconds", t.linear_seconds},
                   {"solve_seconds", t.total_seconds},
                   {"stress_recovery_seconds", recovery_seconds_},
                   {"stress_summary_seconds", stress_summary_seconds_},
                   {"state_file_seconds", state_file_seconds_},
                   {"peak_memory_mib_per_rank", peak_mib},
                   {"setup_memory_mib_per_rank", setup_mib},
                   {"petsc_messages_per_rank", messages},
                   {"petsc_message_mib_per_rank", message_mib},
                   {"held_nodes_per_rank", held},
                   {"note",
                    "assembly_seconds includes contact_seconds; solve_seconds = assembly + linear + the rest; "
                    "contact_reply_seconds: the stent contact's replies and per-step gaps, after the solves; "
                    "interface_product*: the interface Newton-Krylov's linearized responses (rank 0's clock), "
                    "of which the solves with the kept factorization (the rest: the contact's forces and planes); "
                    "state_file_seconds: the state file's writes (every rank writes its block); "
                    "*_per_rank in rank order, so far in the run: the peak resident set (getrusage), the same before "
                    "the first solve (setup: libraries, the mesh, the model, the matrix's pattern, the contact's "
                    "structures), PETSc's messages and their volume as -log_view counts them (not MUMPS' own "
                    "traffic), and the nodes whose displacement the rank holds (its own, the other nodes of its "
                    "elements and faces, the contact surfaces' and the measured ones)"}};
  }
  j["steps"] = ordered_json::array();
  for (const auto& s : history_) {
    ordered_json e;
    e["step"] = s.step;
    e["time"] = s.time;
    for (const auto& [label, p] : s.pressures) e[label] = p;
    ordered_json mx, p99, where;
    for (size_t b = 0; b < s.max_p1.size(); ++b) {
      mx[mesh.blocks[b].name] = finite(s.max_p1[b]);
      if (b < s.stress.size()) {
        p99[mesh.blocks[b].name] = finite(s.stress[b].p99);
        const Vec3d& w = s.stress[b].where;
        where[mesh.blocks[b].name] = {w(0), w(1), w(2)};
      }
    }
    e["max_principal_stress"] = mx;
    e["p99_principal_stress"] = p99;
    e["max_principal_stress_at"] = where;
    ordered_json avg, where_avg;
    for (size_t b = 0; b < s.stress.size(); ++b) {
      const auto& bs = s.stress[b];
      avg[mesh.blocks[b].name] = finite(bs.max_averaged);
      where_avg[mesh.blocks[b].name] = {bs.where_averaged(0), bs.where_averaged(1), bs.where_averaged(2)};
    }
    e["max_principal_stress_averaged"] = avg;
    e["max_principal_stress_averaged_at"] = where_avg;
    ordered_json mxn, p99n, wheren, endo;
    for (size_t b = 0; b < s.stress.size(); ++b) {
      const auto& bs = s.stress[b];
      const std::string& name = mesh.blocks[b].name;
      mxn[name] = finite(bs.max_nodal);
      p99n[name] = finite(bs.p99_nodal);
      wheren[name] = {bs.where_nodal(0), bs.where_nodal(1), bs.where_nodal(2)};
      if (std::isfinite(bs.max_endothelium_nodal)) endo[name] = bs.max_endothelium_nodal;
    }
    e["max_principal_stress_nodal"] = mxn;
    e["p99_principal_stress_nodal"] = p99n;
    e["max_principal_stress_nodal_at"] = wheren;
    if (!endo.is_null()) e["max_principal_stress_endothelium_nodal"] = endo;
    for (const auto& [part, u] : s.max_displacement) e["max_displacement"][part] = u;
    if (scene_.balloon_diameter) {
      const double dog = s.d_mid > 0 ? (0.5 * (s.d_end0 + s.d_end1) - s.d_mid) / s.d_mid : 0.0;
      e["balloon_outer_diameter"] = {{"mid", s.d_mid}, {"end0", s.d_end0}, {"end1", s.d_end1}, {"dogboning", dog}};
    }
    if (!s.lumen_diameter.empty()) {
      e["lumen_diameter"] = s.lumen_diameter;
      const auto [lo, hi] = std::minmax_element(s.lumen_diameter.begin(), s.lumen_diameter.end());
      e["lumen_diameter_min"] = *lo;
      e["lumen_diameter_max"] = *hi;
      auto& c = e["lumen_centroid"] = ordered_json::array();
      for (const auto& v : s.lumen_centroid) c.push_back({v.x(), v.y(), v.z()});
    }
    if (s.stent_stations) e["stent_stations"] = {s.stent_stations->first, s.stent_stations->second};
    for (const auto& [name, f] : s.artery_contact_force) e["artery_contact_force"][name] = f;
    if (s.apposition) {
      const auto& a = *s.apposition;
      e["apposition"] = {{"stent_length", a.length},
                         {"malapposed_length", a.malapposed_length},
                         {"malapposed_fraction", a.malapposed_fraction},
                         {"max_gap", finite(a.max_gap)},
                         {"mean_gap", finite(a.mean_gap)}};
    }
    e["newton_iterations"] = s.newton_iterations;
    e["residual"] = s.residual;
    e["wall_seconds"] = s.solve_seconds;
    j["steps"].push_back(std::move(e));
  }
  const std::string tmp = dir_ + "/summary.json.tmp";
  {
    std::ofstream f(tmp);
    f << j.dump(1) << "\n";
  }
  std::rename(tmp.c_str(), (dir_ + "/summary.json").c_str());
}

void SolidRunner::write_state_() {
  if (!writer_ || !scene_.output.state || state_step_ == committed_) return;
  state_step_ = committed_;
  const double t0 = MPI_Wtime();
  try {  // every rank writes its block; HDF5 fails on all of them alike, which must not stop the run
    write_state_file(*model_, dir_ + "/state.h5", committed_);
  } catch (const std::exception& e) {
    LOG_WARN("solid: state file not written at step " << committed_ << ": " << e.what()
                                                      << " (the previous one, if any, is kept)");
  }
  state_file_seconds_ += MPI_Wtime() - t0;
}

void SolidRunner::finish() {
  if (finished_) return;
  finished_ = true;
  write_state_();
  write_summary_();  // the timing of the solves after the last commit and of that state file
  if (writer_) writer_->close();
}

// ---------------------------------------------------------------------------------------------
namespace {
enum Cmd : int { kBegin = 1, kSolve = 2, kEnd = 3, kFinish = 4, kLinear = 5 };

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
                                                   participant::ContactReply& reply, double tolerance) {
  int cmd = kSolve;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  MPI_Bcast(&tolerance, 1, MPI_DOUBLE, 0, comm_);
  participant::SamplePoints p = pts;
  if (p.w.size() != p.x.size()) p.w.resize(p.x.size(), 0.0);
  if (p.radius.size() != p.x.size()) p.radius.resize(p.x.size(), 0.0);
  bcast_points(p, comm_);
  return inner_.solve(p, reply, tolerance);
}

participant::SolveStats MpiSolidParticipant::linear_response(const std::vector<participant::Vec3>& dx,
                                                             std::vector<double>& plane_shift,
                                                             std::vector<participant::Vec3>& normal_turn) {
  int cmd = kLinear;
  MPI_Bcast(&cmd, 1, MPI_INT, 0, comm_);
  std::vector<participant::Vec3> d = dx;
  long n = long(d.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm_);
  if (n > 0) MPI_Bcast(d.data(), int(3 * n), MPI_DOUBLE, 0, comm_);
  return inner_.linear_response(d, plane_shift, normal_turn);
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
        double tolerance = 0.0;
        MPI_Bcast(&tolerance, 1, MPI_DOUBLE, 0, comm);
        participant::SamplePoints p;
        bcast_points(p, comm);
        participant::ContactReply reply;
        inner.solve(p, reply, tolerance);
        break;
      }
      case kLinear: {
        long n = 0;
        MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
        std::vector<participant::Vec3> d(static_cast<std::size_t>(n));
        if (n > 0) MPI_Bcast(d.data(), int(3 * n), MPI_DOUBLE, 0, comm);
        std::vector<double> shift;
        std::vector<participant::Vec3> turn;
        inner.linear_response(d, shift, turn);
        break;
      }
      case kEnd: {
        int a;
        MPI_Bcast(&a, 1, MPI_INT, 0, comm);
        inner.end_step(a != 0);
        break;
      }
      case kFinish:
        inner.finish();
        return 0;
      default:
        return 1;
    }
  }
}

}  // namespace angio::solid
