#include "angio/solid/stent_contact.hpp"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <utility>

#include "angio/contact/normal_field.hpp"
#include "angio/solid/model.hpp"
#include "petsc_check.hpp"

namespace angio::solid {

namespace {

// The current positions of the contact's nodes (its own numbering: contact node i is mesh node nodes[i],
// which the model holds on every rank).
void gather_coords(const SolidModel& model, const std::vector<int>& nodes, std::vector<contact::Vec3>& coords) {
  coords.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) coords[i] = model.position(nodes[i]);
}

// Whether the model's positions of `nodes` are bit for bit `coords` (the configuration an evaluation saw).
bool same_positions(const SolidModel& model, const std::vector<int>& nodes, const std::vector<contact::Vec3>& coords) {
  if (coords.size() != nodes.size()) return false;
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (coords[i] != model.position(nodes[i])) return false;
  return true;
}

// Renumbers the surfaces' faces to the contact's own node numbering and returns the mesh node of each
// contact node (ascending, so the numbering keeps the mesh's order): the coordinate arrays, the nodal
// normals and the searches then hold the surfaces' nodes, not the whole mesh's.
std::vector<int> renumber(std::span<contact::Surface* const> surfaces) {
  std::vector<int> nodes;
  for (const contact::Surface* s : surfaces)
    for (const auto& f : s->faces) nodes.insert(nodes.end(), f.nodes.begin(), f.nodes.begin() + f.nn());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (contact::Surface* s : surfaces)
    for (auto& f : s->faces)
      for (int a = 0; a < f.nn(); ++a)
        f.nodes[a] = int(std::lower_bound(nodes.begin(), nodes.end(), f.nodes[a]) - nodes.begin());
  return nodes;
}

// Appends the mesh nodes of contact nodes `ids` to out.
void append_mesh_nodes(std::vector<int>& out, const std::vector<int>& nodes, std::span<const int> ids) {
  for (int id : ids) out.push_back(nodes[id]);
}

// Adds contributions (r = dPi/dX on the first r.size()/3 nodes, K = dr/dX over all nodes; their nodes in the
// contact's numbering, mesh node nodes[i]) with the model's global dof numbers. Eigen's column-major K goes in
// as is: the model's Mat is column-oriented.
void insert(const SolidModel& model, const std::vector<int>& nodes, const std::vector<contact::NodalContribution>& cs,
            Vec r, Mat K) {
  std::vector<PetscInt> idx;
  for (const auto& c : cs) {
    const int rows = int(c.r.size()), m = 3 * int(c.nodes.size());
    idx.resize(m);
    for (size_t a = 0; a < c.nodes.size(); ++a)
      for (int k = 0; k < 3; ++k) idx[3 * a + k] = model.dof(nodes[c.nodes[a]], k);
    ANGIO_PETSC(VecSetValues(r, rows, idx.data(), c.r.data(), ADD_VALUES));
    if (K && c.K.size() > 0) {
      if (c.K.rows() != rows || c.K.cols() != m) throw std::logic_error("contact contribution: tangent size mismatch");
      ANGIO_PETSC(MatSetValues(K, rows, idx.data(), m, idx.data(), c.K.data(), ADD_VALUES));
    }
  }
}

// Global diagnostics from the per-rank slices (sums, min gap), same on every rank.
ContactSummary reduce_summary(const contact::ContactDiagnostics& d, double area, double radius, MPI_Comm comm,
                              double* area_out) {
  double sum[8] = {double(d.num_points),
                   double(d.num_active),
                   d.force_on_solid(0),
                   d.force_on_solid(1),
                   d.force_on_solid(2),
                   d.force_magnitude,
                   d.energy,
                   area};
  double g[8];
  MPI_Allreduce(sum, g, 8, MPI_DOUBLE, MPI_SUM, comm);
  double mn = d.min_gap, gmn;
  MPI_Allreduce(&mn, &gmn, 1, MPI_DOUBLE, MPI_MIN, comm);
  ContactSummary s;
  s.num_points = int(g[0]);
  s.num_active = int(g[1]);
  s.force = std::sqrt(g[2] * g[2] + g[3] * g[3] + g[4] * g[4]);
  s.force_magnitude = g[5];
  s.energy = g[6];
  s.min_gap = std::isfinite(gmn) ? gmn : radius;
  if (area_out) *area_out = g[7];
  return s;
}

// Contiguous slice [lo, hi) of n items for this rank.
void slice(std::size_t n, int rank, int size, std::size_t& lo, std::size_t& hi) {
  lo = n * std::size_t(rank) / std::size_t(size);
  hi = n * std::size_t(rank + 1) / std::size_t(size);
}

// Every rank's slice of n items (`record` doubles each, this rank's in `mine`) in item order on rank 0;
// empty on the other ranks. Collective.
std::vector<double> gather_slices(const SolidModel& model, std::size_t n, std::size_t record,
                                  const std::vector<double>& mine) {
  const int size = model.size();
  if (size == 1) return mine;
  std::vector<int> counts(size), displs(size);
  for (int r = 0; r < size; ++r) {
    std::size_t lo, hi;
    slice(n, r, size, lo, hi);
    counts[r] = int(record * (hi - lo));
    displs[r] = int(record * lo);
  }
  std::vector<double> all(model.rank() == 0 ? n * record : 0);
  MPI_Gatherv(mine.data(), int(mine.size()), MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, 0,
              model.comm());
  return all;
}

}  // namespace

contact::Surface to_contact_surface(const SurfaceSet& s, double normal_sign) {
  contact::Surface c{s.name, {}, normal_sign};
  c.faces.reserve(s.faces.size());
  for (const Face& f : s.faces) {
    contact::Face g;
    g.kind = to_contact(f.type);
    std::copy(f.n.begin(), f.n.begin() + f.nn(), g.nodes.begin());
    c.faces.push_back(g);
  }
  return c;
}

// ------------------------------------------------------------------------------------------------
// Stent line-to-surface contact

PenaltyStentContact::PenaltyStentContact(const SolidModel& model, Options opt) : opt_(std::move(opt)) {
  if (!(opt_.search_radius > 0)) throw std::runtime_error("stent contact: search radius must be positive");
  auto add_surface = [&](const std::string& name, std::optional<double> eps, double from) {
    if (!eps) return;
    const SurfaceSet* s = model.mesh().surface(name);
    if (!s || s->faces.empty()) return;
    surfaces_.push_back(std::make_unique<contact::Surface>(to_contact_surface(*s, +1.0)));
    names_.push_back(name);
    penalty_.push_back(*eps);
    from_.push_back(from);
  };
  add_surface(opt_.balloon_surface, opt_.balloon_penalty, opt_.balloon_from);
  add_surface(opt_.artery_surface, opt_.artery_penalty, opt_.artery_from);
  std::vector<contact::Surface*> surfaces;
  for (const auto& sf : surfaces_) surfaces.push_back(sf.get());
  nodes_ = renumber(surfaces);  // before the searches, which key the free edges by node
  for (const auto& sf : surfaces_) {
    searches_.push_back(std::make_unique<contact::SurfaceSearch>(*sf, opt_.search_radius));
    searches_.back()->enable_normal_field(opt_.averaged_normals);
  }
  last_.min_gap = opt_.search_radius;
}

PenaltyStentContact::~PenaltyStentContact() = default;

void PenaltyStentContact::set_points(const participant::SamplePoints& pts) {
  if (pts.w.size() != pts.x.size() || pts.radius.size() != pts.x.size())
    throw std::runtime_error("stent contact: sample points need x, w and radius of equal length");
  last_eval_.clear();
  // hints of the same points stay (they moved little); a new set of points starts without
  if (hints_.empty() || pts.x.size() != points_.size())
    hints_.assign(searches_.size(), std::vector<contact::ProjectionHint>(pts.x.size()));
  built_.assign(searches_.size(), 0);
  points_.resize(pts.x.size());
  for (size_t i = 0; i < pts.x.size(); ++i)
    points_[i] = contact::BeamPoint{contact::Vec3(pts.x[i][0], pts.x[i][1], pts.x[i][2]), pts.w[i], pts.radius[i]};
}

bool PenaltyStentContact::on_(std::size_t k, const SolidModel& model) const { return model.time() >= from_[k]; }

void PenaltyStentContact::load_levels(double t, std::vector<double>& out) const {
  for (double from : from_) out.push_back(t >= from);
}

std::vector<contact::LineContactResult> PenaltyStentContact::evaluate_(const SolidModel& model,
                                                                       std::span<const contact::BeamPoint> points,
                                                                       std::size_t first, bool tangent, bool all) {
  std::vector<contact::LineContactResult> per_surface;
  if (points.empty() || searches_.empty()) return per_surface;
  gather_coords(model, nodes_, coords_);
  for (size_t k = 0; k < searches_.size(); ++k) {
    if (!all && !on_(k, model)) continue;
    searches_[k]->update(coords_, /*rebuild=*/!built_[k], /*normal_derivatives=*/tangent);
    built_[k] = 1;
    const contact::SurfaceSearch* one[] = {searches_[k].get()};
    contact::LineContactParams par;
    par.penalty = on_(k, model) ? penalty_[k] : 0.0;
    par.regularization = opt_.regularization;
    par.averaged_normals = opt_.averaged_normals;
    par.ring_tangent = opt_.ring_tangent;
    par.force_tangent = opt_.force_tangent;
    par.definite_force_terms = opt_.definite_force_terms;
    par.compute_tangent = tangent;
    const std::span<contact::ProjectionHint> hint[] = {std::span(hints_[k]).subspan(first, points.size())};
    per_surface.push_back(contact::evaluate_line_contact(points, one, par, hint));
  }
  return per_surface;
}

void PenaltyStentContact::add(const SolidModel& model, Vec r, Mat K) {
  const double t0 = MPI_Wtime();
  // every rank holds all coordinates: each evaluates a contiguous slice of the points against the whole
  // surfaces and adds its own contributions (each enters the global system exactly once)
  std::size_t lo, hi;
  slice(points_.size(), model.rank(), model.size(), lo, hi);
  contact::ContactDiagnostics diag;
  auto per_surface = evaluate_(model, std::span(points_).subspan(lo, hi - lo), lo, K != nullptr, false);
  for (auto& res : per_surface) {
    insert(model, nodes_, res.solid, r, K);
    diag.merge(res.diag);
    res.solid.clear();  // the reply needs the points' results only
  }
  last_ = reduce_summary(diag, 0.0, opt_.search_radius, model.comm(), nullptr);
  last_eval_.clear();
  if (per_surface.size() == searches_.size()) {  // every pair on: the reply's evaluation of this slice
    last_eval_ = std::move(per_surface);
    std::swap(last_eval_coords_, coords_);  // no copy: the next evaluation gathers coords_ anew
  }
  timing_.calls++;
  timing_.seconds += MPI_Wtime() - t0;
}

std::vector<NodeCoupling> PenaltyStentContact::couplings(const SolidModel& model) const {
  std::vector<NodeCoupling> out;
  if (!opt_.averaged_normals || !opt_.ring_tangent) return out;  // face columns: the elements' pattern has them
  for (const auto& surface : surfaces_) {
    const auto ring = contact::node_rings(*surface, nodes_.size());
    for (const auto& f : surface->faces) {
      NodeCoupling c;
      append_mesh_nodes(c.rows, nodes_, std::span(f.nodes).first(f.nn()));
      for (int a = 0; a < f.nn(); ++a) append_mesh_nodes(c.cols, nodes_, ring[f.nodes[a]]);
      std::sort(c.cols.begin(), c.cols.end());
      c.cols.erase(std::unique(c.cols.begin(), c.cols.end()), c.cols.end());
      out.push_back(std::move(c));
    }
  }
  return out;
}

void PenaltyStentContact::fill_reply(const SolidModel& model, participant::ContactReply& reply) {
  const size_t n = points_.size();
  if (reply.line_loads.size() != n)
    throw std::logic_error("stent contact: fill_reply needs a reply reset_reply() for the points of set_points()");
  reply.n_active = 0;
  reply.min_gap = opt_.search_radius;
  reply.total_force = {0.0, 0.0, 0.0};
  const size_t K = searches_.size();
  if (n == 0 || K == 0) return;
  // Each rank evaluates its slice of the points (the last assembly's evaluation when it saw this
  // configuration: a converged Newton's last residual), rank 0 gathers them: per point the line load
  // q and, per surface, whether it has a plane, whether the point is active, the plane's point and
  // normal and the gap.
  std::size_t lo, hi;
  slice(n, model.rank(), model.size(), lo, hi);
  const bool reuse = !last_eval_.empty() && same_positions(model, nodes_, last_eval_coords_);
  const auto per_surface =
      reuse ? std::move(last_eval_) : evaluate_(model, std::span(points_).subspan(lo, hi - lo), lo, false, true);
  last_eval_.clear();
  constexpr size_t kPerSurface = 9;
  const size_t record = 3 + kPerSurface * K;
  std::vector<double> mine;
  mine.reserve(record * (hi - lo));
  for (size_t i = 0; i < hi - lo; ++i) {
    contact::Vec3 q = contact::Vec3::Zero();
    for (size_t k = 0; k < K; ++k) q += per_surface[k].q[i];
    mine.insert(mine.end(), {q(0), q(1), q(2)});
    for (size_t k = 0; k < K; ++k) {
      const auto& pc = per_surface[k].per_surface[0][i];
      const bool plane = pc.found && on_(k, model);  // no plane (eps 0) where the pair is off
      mine.insert(mine.end(), {double(plane), double(plane && pc.active), pc.proj.s(0), pc.proj.s(1), pc.proj.s(2),
                               pc.proj.n(0), pc.proj.n(1), pc.proj.n(2), pc.gap});
    }
  }
  const std::vector<double> all = gather_slices(model, n, record, mine);
  if (model.rank() != 0) return;
  // robin data: one plane per point and surface (K = number of surfaces, point-major), eps = 0 where
  // the surface has no face within the search radius
  reply.surface_points.assign(K * n, {0.0, 0.0, 0.0});
  reply.normals.assign(K * n, {0.0, 0.0, 0.0});
  reply.penalty.assign(K * n, 0.0);
  reply.regularization = opt_.regularization;
  for (size_t i = 0; i < n; ++i) {
    const double* p = all.data() + i * record;
    bool active = false;
    for (size_t k = 0; k < K; ++k) {
      const double* c = p + 3 + kPerSurface * k;
      const size_t j = i * K + k;
      reply.surface_points[j] = {points_[i].x(0), points_[i].x(1), points_[i].x(2)};
      if (c[0] == 0.0) continue;
      active = active || c[1] != 0.0;
      reply.surface_points[j] = {c[2], c[3], c[4]};
      reply.normals[j] = {c[5], c[6], c[7]};
      reply.penalty[j] = penalty_[k];
      reply.min_gap = std::min(reply.min_gap, c[8]);
    }
    reply.line_loads[i] = {p[0], p[1], p[2]};
    for (int c = 0; c < 3; ++c) reply.total_force[c] += points_[i].w * p[c];
    reply.active[i] = active ? 1 : 0;
    reply.n_active += active ? 1 : 0;
  }
}

void PenaltyStentContact::gaps(const SolidModel& model, const std::string& surface, std::vector<double>& gap,
                               std::vector<double>& weight) {
  gap.clear();
  weight.clear();
  const auto it = std::find(names_.begin(), names_.end(), surface);
  if (it == names_.end() || points_.empty()) return;
  std::size_t lo, hi;  // each rank its slice, gathered on rank 0
  slice(points_.size(), model.rank(), model.size(), lo, hi);
  const auto per_surface = evaluate_(model, std::span(points_).subspan(lo, hi - lo), lo, false, true);
  std::vector<double> mine(hi - lo);
  for (size_t i = 0; i < hi - lo; ++i) {
    const auto& pc = per_surface[it - names_.begin()].per_surface[0][i];
    mine[i] = pc.found ? pc.gap : std::numeric_limits<double>::infinity();
  }
  gap = gather_slices(model, points_.size(), 1, mine);
  if (model.rank() == 0)
    for (const auto& p : points_) weight.push_back(p.w);
}

// ------------------------------------------------------------------------------------------------
// Balloon-artery surface-to-surface contact

PenaltySurfaceContact::PenaltySurfaceContact(const SolidModel& model, Options opt) : opt_(std::move(opt)) {
  const SurfaceSet* s = model.mesh().surface(opt_.slave);
  const SurfaceSet* m = model.mesh().surface(opt_.master);
  if (!s) throw std::runtime_error("surface contact: no surface set '" + opt_.slave + "'");
  if (!m) throw std::runtime_error("surface contact: no surface set '" + opt_.master + "'");
  if (!(opt_.search_radius > 0)) throw std::runtime_error("surface contact: search radius must be positive");
  slave_ = std::make_unique<contact::Surface>(to_contact_surface(*s, +1.0));
  master_ = std::make_unique<contact::Surface>(to_contact_surface(*m, +1.0));
  if (!opt_.two_pass) {
    // one pass: the slave search is not used as a master, so each rank can own a slice of the slave faces
    std::size_t lo, hi;
    slice(slave_->faces.size(), model.rank(), model.size(), lo, hi);
    slave_->faces = std::vector<contact::Face>(slave_->faces.begin() + lo, slave_->faces.begin() + hi);
  }
  contact::Surface* both[] = {slave_.get(), master_.get()};
  nodes_ = renumber(both);  // this rank's slice of the slave's, with one pass; before the searches
  if (!slave_->faces.empty()) ss_ = std::make_unique<contact::SurfaceSearch>(*slave_, opt_.search_radius);
  sm_ = std::make_unique<contact::SurfaceSearch>(*master_, opt_.search_radius);
  last_.min_gap = opt_.search_radius;
}

PenaltySurfaceContact::~PenaltySurfaceContact() = default;

void PenaltySurfaceContact::evaluate_(const SolidModel& model, bool tangent) {
  const double t0 = MPI_Wtime();
  contact::ContactDiagnostics diag;
  double area = 0.0;
  evaluated_ = {};
  evaluated_tangent_ = tangent;
  // one pass: every rank its slice of slave faces; two_pass: rank 0 evaluates everything; nothing
  // while the pair is off (the same time on every rank: the reduction below stays collective)
  const bool mine = model.time() >= opt_.from && (opt_.two_pass ? model.rank() == 0 : ss_ != nullptr);
  if (mine) {
    gather_coords(model, nodes_, coords_);
    ss_->update(coords_);
    sm_->update(coords_);
    contact::SurfaceContactParams par;
    par.penalty = opt_.penalty;
    par.quadrature_degree = opt_.quadrature;
    par.regularization = opt_.regularization;
    par.two_pass = opt_.two_pass;
    par.compute_tangent = tangent;
    evaluated_ = contact::evaluate_surface_contact(*ss_, *sm_, par);
    diag = evaluated_.diag;
    area = evaluated_.active_area;
  }
  last_ = reduce_summary(diag, area, opt_.search_radius, model.comm(), &active_area_);
  timing_.calls++;
  timing_.seconds += MPI_Wtime() - t0;
}

std::vector<NodeCoupling> PenaltySurfaceContact::prepare(const SolidModel& model, bool tangent) {
  evaluate_(model, tangent);
  prepared_ = true;
  std::vector<NodeCoupling> out;
  if (!tangent) return out;
  // Pairs enter the pattern in batches: when a pair that contributes (an active Gauss point) is not in
  // it yet, every pair within the search radius that is not in it goes in too, so the pairs around a
  // growing contact zone are there before they touch; while no new pair contributes, the matrix is not
  // rebuilt. (Every pair on entering the radius cost 83 rebuilds in 103 tangent assemblies of the
  // 0.25 mm patient artery before the balloon touched it, ~0.85 s each: docs/performance.md,
  // "Element insertion".)
  auto key_of = [](const contact::GaussPointContact& gp) {
    return (std::uint64_t(gp.pass) << 62) | (std::uint64_t(gp.slave_face) << 31) | std::uint64_t(gp.master_face);
  };
  bool new_contact = false;
  for (const auto& gp : evaluated_.points) new_contact = new_contact || (gp.active && !paired_.count(key_of(gp)));
  if (!new_contact) return out;
  for (const auto& gp : evaluated_.points) {
    if (!paired_.insert(key_of(gp)).second) continue;
    const contact::Face& fs = (gp.pass == 0 ? *slave_ : *master_).faces[gp.slave_face];
    const contact::Face& fm = (gp.pass == 0 ? *master_ : *slave_).faces[gp.master_face];
    std::vector<int> nodes;
    append_mesh_nodes(nodes, nodes_, std::span(fs.nodes).first(fs.nn()));
    append_mesh_nodes(nodes, nodes_, std::span(fm.nodes).first(fm.nn()));
    out.push_back({nodes, nodes});
  }
  return out;
}

void PenaltySurfaceContact::add(const SolidModel& model, Vec r, Mat K) {
  // what prepare() evaluated: the model calls it right before (ContactModel::prepare); a call on its own
  // (or one that needs the tangent prepare() did not compute) evaluates now
  if (!prepared_ || (K && !evaluated_tangent_)) evaluate_(model, K != nullptr);
  prepared_ = false;
  insert(model, nodes_, evaluated_.contributions, r, K);
}

// ------------------------------------------------------------------------------------------------

void CompositeContact::set_points(const participant::SamplePoints& points) {
  if (stent_) stent_->set_points(points);
}

void CompositeContact::add(const SolidModel& model, Vec r, Mat K) {
  if (stent_) stent_->add(model, r, K);
  for (auto* m : others_) m->add(model, r, K);
}

namespace {
// What `of` returns for each model (couplings, nodes), the stent's first, concatenated.
template <class Of>
auto all_of(ContactModel* stent, const std::vector<ContactModel*>& others, Of of) {
  decltype(of(*stent)) out = stent ? of(*stent) : decltype(of(*stent)){};
  for (auto* m : others) {
    auto c = of(*m);
    out.insert(out.end(), std::make_move_iterator(c.begin()), std::make_move_iterator(c.end()));
  }
  return out;
}
}  // namespace

std::vector<NodeCoupling> CompositeContact::couplings(const SolidModel& model) const {
  return all_of(stent_, others_, [&](ContactModel& m) { return m.couplings(model); });
}

std::vector<int> CompositeContact::held_nodes(const SolidModel& model) const {
  return all_of(stent_, others_, [&](ContactModel& m) { return m.held_nodes(model); });
}

std::vector<NodeCoupling> CompositeContact::prepare(const SolidModel& model, bool tangent) {
  return all_of(stent_, others_, [&](ContactModel& m) { return m.prepare(model, tangent); });
}

void CompositeContact::load_levels(double t, std::vector<double>& out) const {
  if (stent_) stent_->load_levels(t, out);
  for (const ContactModel* m : others_) m->load_levels(t, out);
}

bool CompositeContact::extrapolates(double from, double to) const {
  if (stent_ && !stent_->extrapolates(from, to)) return false;
  for (const ContactModel* m : others_)
    if (!m->extrapolates(from, to)) return false;
  return true;
}

void CompositeContact::fill_reply(const SolidModel& model, participant::ContactReply& reply) {
  if (stent_) stent_->fill_reply(model, reply);
  if (after_reply) after_reply(model, reply);
}

void CompositeContact::gaps(const SolidModel& model, const std::string& surface, std::vector<double>& gap,
                            std::vector<double>& weight) {
  if (stent_)
    stent_->gaps(model, surface, gap, weight);
  else
    StentContact::gaps(model, surface, gap, weight);
}

}  // namespace angio::solid
