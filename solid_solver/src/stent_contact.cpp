#include "angio/solid/stent_contact.hpp"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "angio/solid/model.hpp"

namespace angio::solid {

namespace {

#define ANGIO_CPETSC(call)                                                                    \
  do {                                                                                        \
    PetscErrorCode ierr_ = (call);                                                            \
    if (ierr_) throw std::runtime_error(std::string("PETSc error in ") + #call + " (code " +   \
                                        std::to_string(int(ierr_)) + ")");                    \
  } while (0)

void gather_coords(const SolidModel& model, std::vector<contact::Vec3>& coords) {
  const int n = int(model.mesh().X.size());
  coords.resize(n);
  for (int i = 0; i < n; ++i) coords[i] = model.position(i);
}

// Adds contributions (r = dPi/dX, K = d2Pi/dX2, symmetric) with the model's global dof numbers.
void insert(const SolidModel& model, const std::vector<contact::NodalContribution>& cs, Vec r, Mat K) {
  std::vector<PetscInt> idx;
  for (const auto& c : cs) {
    const int m = 3 * int(c.nodes.size());
    idx.resize(m);
    for (size_t a = 0; a < c.nodes.size(); ++a)
      for (int k = 0; k < 3; ++k) idx[3 * a + k] = model.dof(c.nodes[a], k);
    ANGIO_CPETSC(VecSetValues(r, m, idx.data(), c.r.data(), ADD_VALUES));
    // K is symmetric: the same values in row- or column-major order (the model's Mat is column-oriented).
    if (K && c.K.rows() == m && c.K.cols() == m) ANGIO_CPETSC(MatSetValues(K, m, idx.data(), m, idx.data(), c.K.data(), ADD_VALUES));
  }
}

// Contact adds couplings between different bodies that the element preallocation does not have.
void allow_new_nonzeros(Mat K) {
  if (K) ANGIO_CPETSC(MatSetOption(K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
}

void bcast_summary(ContactSummary& s, MPI_Comm comm) {
  double b[7] = {double(s.num_points), double(s.num_active), s.min_gap, s.force, s.force_magnitude, s.energy, 0.0};
  MPI_Bcast(b, 7, MPI_DOUBLE, 0, comm);
  s.num_points = int(b[0]);
  s.num_active = int(b[1]);
  s.min_gap = b[2];
  s.force = b[3];
  s.force_magnitude = b[4];
  s.energy = b[5];
}

ContactSummary summarize(const contact::ContactDiagnostics& d, double radius) {
  ContactSummary s;
  s.num_points = d.num_points;
  s.num_active = d.num_active;
  s.min_gap = std::isfinite(d.min_gap) ? d.min_gap : radius;
  s.force = d.force_on_solid.norm();
  s.force_magnitude = d.force_magnitude;
  s.energy = d.energy;
  return s;
}

}  // namespace

contact::Surface to_contact_surface(const SurfaceSet& s, double normal_sign) {
  contact::Surface c{s.name, {}, normal_sign};
  c.faces.reserve(s.faces.size());
  for (const Face& f : s.faces) {
    contact::Face g;
    switch (f.type) {
      case FaceType::Quad4: g.kind = contact::FaceKind::Quad4; break;
      case FaceType::Tri3: g.kind = contact::FaceKind::Tri3; break;
      case FaceType::Tri6: g.kind = contact::FaceKind::Tri6; break;

    }
    if (g.nn() != f.nn()) throw std::runtime_error("contact: face node count mismatch on '" + s.name + "'");
    std::copy(f.n.begin(), f.n.begin() + f.nn(), g.nodes.begin());
    c.faces.push_back(g);
  }
  return c;
}

void reset_reply(const participant::SamplePoints& pts, participant::ContactReply& reply) {
  const size_t n = pts.x.size();
  reply = participant::ContactReply{};
  reply.line_loads.assign(n, {0.0, 0.0, 0.0});
  reply.surface_points = pts.x;
  reply.normals.assign(n, {0.0, 0.0, 0.0});
  reply.penalty.assign(n, 0.0);
  reply.active.assign(n, 0);
}

// ------------------------------------------------------------------------------------------------
// Stent line-to-surface contact

struct PenaltyStentContact::Eval {
  std::vector<contact::LineContactResult> per_surface;  // one evaluation per surface (own penalty)
  contact::ContactDiagnostics diag;
};

PenaltyStentContact::PenaltyStentContact(const SolidModel& model, Options opt) : opt_(std::move(opt)) {
  if (!(opt_.search_radius > 0)) throw std::runtime_error("stent contact: search radius must be positive");
  auto add_surface = [&](const std::string& name, std::optional<double> eps) {
    if (!eps) return;
    const SurfaceSet* s = model.mesh().surface(name);
    if (!s || s->faces.empty()) return;
    surfaces_.push_back(std::make_unique<contact::Surface>(to_contact_surface(*s, +1.0)));
    searches_.push_back(std::make_unique<contact::SurfaceSearch>(*surfaces_.back(), opt_.search_radius));
    names_.push_back(name);
    penalty_.push_back(*eps);
  };
  add_surface(opt_.balloon_surface, opt_.balloon_penalty);
  add_surface(opt_.artery_surface, opt_.artery_penalty);
  last_.min_gap = opt_.search_radius;
}

PenaltyStentContact::~PenaltyStentContact() = default;

void PenaltyStentContact::set_points(const participant::SamplePoints& pts) {
  if (pts.w.size() != pts.x.size() || pts.radius.size() != pts.x.size())
    throw std::runtime_error("stent contact: sample points need x, w and radius of equal length");
  points_.resize(pts.x.size());
  for (size_t i = 0; i < pts.x.size(); ++i)
    points_[i] = contact::BeamPoint{contact::Vec3(pts.x[i][0], pts.x[i][1], pts.x[i][2]), pts.w[i], pts.radius[i]};
}

void PenaltyStentContact::evaluate_(const SolidModel& model, bool tangent, Eval& out) {
  out.per_surface.clear();
  out.diag = {};
  if (points_.empty() || searches_.empty()) return;
  gather_coords(model, coords_);
  for (size_t k = 0; k < searches_.size(); ++k) {
    searches_[k]->update(coords_, /*rebuild=*/true);
    const contact::SurfaceSearch* one[] = {searches_[k].get()};
    contact::LineContactParams par;
    par.penalty = penalty_[k];
    par.compute_tangent = tangent;
    out.per_surface.push_back(contact::evaluate_line_contact(points_, one, par));
    out.diag.merge(out.per_surface.back().diag);
  }
}

void PenaltyStentContact::add(const SolidModel& model, Vec r, Mat K) {
  const double t0 = MPI_Wtime();
  allow_new_nonzeros(K);
  ContactSummary s;
  s.min_gap = opt_.search_radius;
  if (model.rank() == 0 && !points_.empty() && !searches_.empty()) {
    Eval e;
    evaluate_(model, K != nullptr, e);
    for (const auto& res : e.per_surface) insert(model, res.solid, r, K);
    s = summarize(e.diag, opt_.search_radius);
  }
  bcast_summary(s, model.comm());
  last_ = s;
  timing_.calls++;
  timing_.seconds += MPI_Wtime() - t0;
}

void PenaltyStentContact::fill_reply(const SolidModel& model, participant::ContactReply& reply) {
  const size_t n = points_.size();
  if (reply.line_loads.size() != n) {
    participant::SamplePoints p;
    for (const auto& b : points_) {
      p.x.push_back({b.x(0), b.x(1), b.x(2)});
      p.w.push_back(b.w);
      p.radius.push_back(b.R);
    }
    reset_reply(p, reply);
  }
  reply.n_active = 0;
  reply.min_gap = opt_.search_radius;
  reply.total_force = {0.0, 0.0, 0.0};
  if (n == 0 || searches_.empty()) return;
  Eval e;
  evaluate_(model, false, e);  // every rank: identical data, no communication
  for (size_t i = 0; i < n; ++i) {
    contact::Vec3 q = contact::Vec3::Zero();
    int best = -1;
    double best_gap = std::numeric_limits<double>::infinity();
    bool active = false;
    for (size_t k = 0; k < e.per_surface.size(); ++k) {
      q += e.per_surface[k].q[i];
      const auto& pc = e.per_surface[k].per_surface[0][i];
      if (!pc.found) continue;
      active = active || pc.active;
      if (pc.gap < best_gap) {
        best_gap = pc.gap;
        best = int(k);
      }
    }
    reply.line_loads[i] = {q(0), q(1), q(2)};
    for (int c = 0; c < 3; ++c) reply.total_force[c] += points_[i].w * q(c);
    if (best >= 0) {
      // robin data: the plane of the surface with the smallest gap (only one plane per point is representable)
      const auto& pc = e.per_surface[best].per_surface[0][i];
      reply.surface_points[i] = {pc.proj.s(0), pc.proj.s(1), pc.proj.s(2)};
      reply.normals[i] = {pc.proj.n(0), pc.proj.n(1), pc.proj.n(2)};
      reply.penalty[i] = penalty_[best];
      reply.min_gap = std::min(reply.min_gap, best_gap);
    }
    reply.active[i] = active ? 1 : 0;
    reply.n_active += active ? 1 : 0;
  }
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
  ss_ = std::make_unique<contact::SurfaceSearch>(*slave_, opt_.search_radius);
  sm_ = std::make_unique<contact::SurfaceSearch>(*master_, opt_.search_radius);
  last_.min_gap = opt_.search_radius;
}

PenaltySurfaceContact::~PenaltySurfaceContact() = default;

void PenaltySurfaceContact::add(const SolidModel& model, Vec r, Mat K) {
  const double t0 = MPI_Wtime();
  allow_new_nonzeros(K);
  ContactSummary s;
  s.min_gap = opt_.search_radius;
  double area = 0.0;
  if (model.rank() == 0) {
    gather_coords(model, coords_);
    ss_->update(coords_);
    sm_->update(coords_);
    contact::SurfaceContactParams par;
    par.penalty = opt_.penalty;
    par.quadrature_degree = opt_.quadrature;
    par.two_pass = opt_.two_pass;
    par.compute_tangent = K != nullptr;
    const auto res = contact::evaluate_surface_contact(*ss_, *sm_, par);
    insert(model, res.contributions, r, K);
    s = summarize(res.diag, opt_.search_radius);
    area = res.active_area;
  }
  bcast_summary(s, model.comm());
  MPI_Bcast(&area, 1, MPI_DOUBLE, 0, model.comm());
  last_ = s;
  active_area_ = area;
  timing_.calls++;
  timing_.seconds += MPI_Wtime() - t0;
}

// ------------------------------------------------------------------------------------------------

void CompositeContact::set_points(const participant::SamplePoints& points) {
  if (stent_) stent_->set_points(points);
}

void CompositeContact::add(const SolidModel& model, Vec r, Mat K) {
  if (stent_) stent_->add(model, r, K);
  for (auto* m : others_) m->add(model, r, K);
}

void CompositeContact::fill_reply(const SolidModel& model, participant::ContactReply& reply) {
  if (stent_) stent_->fill_reply(model, reply);
  if (after_reply) after_reply(model, reply);
}

}  // namespace angio::solid
