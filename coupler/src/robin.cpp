#include "angio/coupler/robin.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "angio/common/log.hpp"
#include "angio/participant/plane_penalty.hpp"
#include "interface_vectors.hpp"

namespace angio::coupler {

Robin::Robin(std::size_t n, bool surface_compliance) : n_(n), compliance_(surface_compliance) {
  set_planes_per_point_(1);
  c_ = c_tilde_ = c_last_ = Eigen::VectorXd::Zero(3 * n);
}

void Robin::set_planes_per_point_(std::size_t K) {
  K_ = K;
  p_.s = p_.n = Eigen::VectorXd::Zero(3 * K * n_);
  p_.eps = Eigen::VectorXd::Zero(K * n_);  // no planes before the solid has answered once
  p_tilde_ = p_last_ = p_before_ = reply_ = first_ = accepted_reply_ = p_;
  k_ = f_first_ = f_reply_ = Eigen::VectorXd::Zero(K * n_);
  softened_last_.assign(K * n_, false);
  softened_before_ = softened_last_;
  k_surface_.assign(K, 0.0);
}

void Robin::begin_step(double increment, bool extrapolate) {
  p_ = p_last_;
  c_ = c_last_;
  have_first_ = false;
  if (!(extrapolate && dt_last_ > 0.0)) return;
  const double f = increment / dt_last_;
  for (Eigen::Index i = 0; i < p_.eps.size(); ++i)
    // not across a change from a bare to a softened plane (or back): their difference is the
    // softening's own shift f/k, and extrapolated it took the wall's planes away from the struts
    if (p_last_.eps[i] > 0.0 && p_before_.eps[i] > 0.0 &&
        softened_last_[std::size_t(i)] == softened_before_[std::size_t(i)]) {
      // plane offset extrapolated along the current normal
      const Eigen::Vector3d n = p_last_.n.segment<3>(3 * i);
      const double d = n.dot(p_last_.s.segment<3>(3 * i) - p_before_.s.segment<3>(3 * i));
      p_.s.segment<3>(3 * i) += f * d * n;
    }
}

participant::SolveStats Robin::solve_beam(participant::BeamParticipant& beam) {
  participant::ContactPlanes planes;
  planes.s = unflatten(p_.s);
  planes.n = unflatten(p_.n);
  planes.eps.assign(p_.eps.data(), p_.eps.data() + p_.eps.size());
  planes.g0 = p_.g0;
  return beam.solve_with_planes(unflatten(c_), planes);
}

Eigen::VectorXd Robin::plane_forces(const participant::SamplePoints& x, const Planes& p) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(p.eps.size());
  const std::size_t K = std::size_t(p.eps.size()) / x.size();
  for (Eigen::Index j = 0; j < p.eps.size(); ++j) {
    if (!(p.eps[j] > 0.0)) continue;
    const std::size_t i = std::size_t(j) / K;
    const Eigen::Vector3d xi(x.x[i][0], x.x[i][1], x.x[i][2]);
    const Eigen::Vector3d n = p.n.segment<3>(3 * j);
    f[j] = participant::plane_penalty(xi, p.s.segment<3>(3 * j), n, p.eps[j], x.radius[i], p.g0).q.dot(n);
  }
  return f;
}

Eigen::VectorXd Robin::loads_of(const Planes& p, const Eigen::VectorXd& f, std::size_t n_points) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3 * n_points);
  const std::size_t K = std::size_t(p.eps.size()) / n_points;
  for (Eigen::Index j = 0; j < f.size(); ++j)
    if (f[j] != 0.0) q.segment<3>(3 * (std::size_t(j) / K)) += f[j] * p.n.segment<3>(3 * j);
  return q;
}

double Robin::stiffness_(Eigen::Index j) const {
  const double median = k_surface_[std::size_t(j) % K_];
  if (!(median > 0.0)) return k_[j];
  if (!(k_[j] > 0.0)) return median;
  // Within a decade of the surface's median: on the post-dilated wall the secants spread over
  // 0.01-12 N/mm^2 about a median of 0.2-0.6, and a plane softened with 0.01 would sit f/k, up to
  // 10 mm, behind the wall. (Measured together with the median fallback, not apart.)
  return std::clamp(k_[j], 0.1 * median, 10.0 * median);
}

Robin::Planes Robin::softened_(const participant::SamplePoints& x, const Planes& p, const Eigen::VectorXd& f) const {
  Planes b = p;
  for (Eigen::Index j = 0; j < p.eps.size(); ++j) {
    const double eps = p.eps[j], k = stiffness_(j);
    if (!(eps > 0.0) || !(k > 0.0)) continue;
    // the series spring of penalty and surface, placed where the unloaded surface would be: it
    // carries the plane's load f_j at x (penalty_gap inverts the law for the new penalty). Taken
    // as estimated: twice as stiff (safe against estimates low by up to 4x in the diagonal model)
    // left the model wall of the tests at 58 instead of 65 iterations (30 as estimated).
    b.eps[j] = eps * k / (eps + k);
    if (!(f[j] > 0.0)) continue;
    const std::size_t i = std::size_t(j) / K_;
    const Eigen::Vector3d n = p.n.segment<3>(3 * j);
    const Eigen::Vector3d xi(x.x[i][0], x.x[i][1], x.x[i][2]);
    const double g = (xi - p.s.segment<3>(3 * j)).dot(n) - x.radius[i];
    b.s.segment<3>(3 * j) += (g - participant::penalty_gap(f[j], p.g0, b.eps[j])) * n;
  }
  return b;
}

void Robin::update_stiffness_() {
  // Secant of each plane's force against its offset over this step's coupling iterations (fixed
  // external loads: what moved the surface is the contact). Only where the force changed by more
  // than 10 % of itself and the surface gave way against it; kept within 1e-3..1e3 of the penalty
  // (a plane dragged along by its neighbours' loads has a meaningless secant).
  for (Eigen::Index j = 0; j < k_.size(); ++j) {
    const double eps = reply_.eps[j];
    if (!(eps > 0.0)) {
      k_[j] = 0.0;  // no surface in range: the estimate belonged to another contact
      continue;
    }
    // in contact at both ends of the secant: a point that just touched moved with its neighbours
    if (!(f_first_[j] > 0.0) || !(f_reply_[j] > 0.0)) continue;
    const Eigen::Vector3d n = reply_.n.segment<3>(3 * j);
    const double dd = n.dot(reply_.s.segment<3>(3 * j) - first_.s.segment<3>(3 * j));
    const double df = f_reply_[j] - f_first_[j];
    if (!(std::abs(df) > 0.1 * std::max(f_reply_[j], f_first_[j])) || !(df * dd < 0.0)) continue;
    const double k = std::clamp(-df / dd, 1e-3 * eps, 1e3 * eps);
    k_[j] = k_[j] > 0.0 ? std::sqrt(k_[j] * k) : k;  // geometric mean with the last estimate: less noise
  }
  // A plane whose own secant never qualified takes its surface's median estimate. A wall that bears
  // on the stent while the balloon pushes elsewhere changes its load by a few per cent per step, so
  // most of its planes would otherwise keep the bare penalty (50x its stiffness: the struts creep
  // into it over 10 coupling iterations per step).
  std::vector<double> ks;
  for (std::size_t s = 0; s < K_; ++s) {
    ks.clear();
    for (std::size_t j = s; j < std::size_t(k_.size()); j += K_)
      if (k_[Eigen::Index(j)] > 0.0) ks.push_back(k_[Eigen::Index(j)]);
    k_surface_[s] = 0.0;
    if (ks.size() >= min_estimates_for_median) {
      std::nth_element(ks.begin(), ks.begin() + std::ptrdiff_t(ks.size() / 2), ks.end());
      k_surface_[s] = ks[ks.size() / 2];
    }
    LOG_DEBUG("robin: surface " << s << ": " << ks.size() << " stiffness estimates, median " << k_surface_[s]
                                << " N/mm^2");
  }
}

Eigen::VectorXd Robin::force_residual(const participant::SamplePoints& x, const participant::ContactReply& reply) {
  const std::size_t n = x.size();
  const std::size_t K = participant::planes_per_point(reply.penalty.size(), n);
  if (K == 0 || reply.surface_points.size() != reply.penalty.size() || reply.normals.size() != reply.penalty.size())
    throw std::runtime_error("robin coupling needs the solid's contact planes (K per point) for all " +
                             std::to_string(n) + " sample points, got " + std::to_string(reply.penalty.size()));
  if (K != K_) {
    if (p_last_.eps.maxCoeff() > 0.0 || p_.eps.maxCoeff() > 0.0)
      throw std::runtime_error("robin coupling: the solid changed the number of contact planes per point from " +
                               std::to_string(K_) + " to " + std::to_string(K) + " during the run");
    set_planes_per_point_(K);
  }
  const Eigen::VectorXd q_tilde = flatten(reply.line_loads);
  const Eigen::VectorXd q_beam = c_ + loads_of(p_, plane_forces(x, p_), n);  // what the beam applied at x
  reply_.s = flatten(reply.surface_points);
  reply_.n = flatten(reply.normals);
  reply_.g0 = reply.regularization;
  reply_.eps = Eigen::Map<const Eigen::VectorXd>(reply.penalty.data(), Eigen::Index(reply.penalty.size()));
  f_previous_ = std::move(f_reply_);  // every reply's forces, the converged ones included
  f_reply_ = plane_forces(x, reply_);
  // the remainder; softened planes carry the same loads at x, so it holds for either
  c_tilde_ = q_tilde - loads_of(reply_, f_reply_, n);
  p_tilde_ = reply_;
  x_ = x;
  if (compliance_) {
    if (!have_first_) {
      first_ = reply_;
      f_first_ = f_reply_;
      have_first_ = true;
    }
    p_tilde_ = softened_(x, reply_, f_reply_);
  }
  return q_tilde - q_beam;
}

void Robin::next_iterate(Acceleration& acc, int k) {
  // Residual of the plane points along the new normals; points without a plane now keep their
  // point (residual 0), points that just got one take it as it is. Either is not the map's
  // response to the iterate, so the acceleration leaves these planes out of its next secant
  // difference: a plane that appears at the edge of the search radius would otherwise jump by up
  // to that radius in the model's columns, and the model moved planes without force into the
  // struts (the generic artery at t = 0.64 s: 0.26 mm, residual 0.007 -> 0.83).
  Eigen::VectorXd r = Eigen::VectorXd::Zero(p_.s.size());
  std::vector<Eigen::Index> jumped;
  for (Eigen::Index i = 0; i < p_.eps.size(); ++i) {
    if ((p_.eps[i] > 0.0) != (p_tilde_.eps[i] > 0.0))
      for (int c = 0; c < 3; ++c) jumped.push_back(3 * i + c);
    if (!(p_tilde_.eps[i] > 0.0)) continue;
    if (!(p_.eps[i] > 0.0)) p_.s.segment<3>(3 * i) = p_tilde_.s.segment<3>(3 * i);
    const Eigen::Vector3d n = p_tilde_.n.segment<3>(3 * i);
    r.segment<3>(3 * i) = n.dot(p_tilde_.s.segment<3>(3 * i) - p_.s.segment<3>(3 * i)) * n;
  }
  LOG_DEBUG("robin: " << jumped.size() / 3 << " planes appeared or vanished");
  if (log::enabled(log::Level::debug)) {
    // per contact surface (plane j of a point): the residual's share and the planes carrying load,
    // to tell which surface holds the coupling back (a balloon leaving the stent, a wall settling)
    const bool have_previous = f_previous_.size() == f_reply_.size();  // not on the run's first reply
    for (std::size_t j = 0; j < K_; ++j) {
      double r2 = 0.0;
      int loaded = 0, switched = 0;
      for (std::size_t i = j; i < std::size_t(p_.eps.size()); i += K_) {
        const Eigen::Index ii = Eigen::Index(i);
        r2 += r.segment<3>(3 * ii).squaredNorm();
        loaded += f_reply_[ii] > 0.0;
        switched += have_previous && (f_reply_[ii] > 0.0) != (f_previous_[ii] > 0.0);
      }
      LOG_DEBUG("robin: surface " << j << ": plane residual " << std::sqrt(r2) << ", " << loaded << " planes loaded, "
                                  << switched << " switched since the last reply");
    }
  }
  if (!acc.uses_jacobian()) {
    acc.mark_discontinuous(std::move(jumped));
    Eigen::VectorXd next = acc.update(p_.s, r, k);
    LOG_DEBUG("robin: plane residual " << r.norm() << ", update " << (next - p_.s).norm());
    p_.s = std::move(next);
    p_.n = p_tilde_.n;
  } else {
    // Newton: the normals are unknowns too. The solid turns them as the surface deforms, and the beam
    // answers a turn (the force's direction) with its soft sliding modes; taken from the last reply
    // as they are, they converge by plain substitution, which the Newton step on the points alone
    // cannot speed up (measured on the straight free expansion's lock-up: the planes' change after a
    // step was twice what their own linearization predicted, all of it from the normals' turn).
    const Eigen::Index m3 = p_.s.size();
    Eigen::VectorXd q(2 * m3), rq = Eigen::VectorXd::Zero(2 * m3);
    q << p_.s, p_.n;
    rq.head(m3) = r;
    for (Eigen::Index i = 0; i < p_.eps.size(); ++i)
      if (p_tilde_.eps[i] > 0.0 && p_.eps[i] > 0.0)
        rq.segment<3>(m3 + 3 * i) = p_tilde_.n.segment<3>(3 * i) - p_.n.segment<3>(3 * i);
    const std::size_t jumped_s = jumped.size();
    for (std::size_t c = 0; c < jumped_s; ++c) jumped.push_back(m3 + jumped[c]);
    acc.mark_discontinuous(std::move(jumped));
    const Eigen::VectorXd next = acc.update(q, rq, k);
    LOG_DEBUG("robin: plane residual " << r.norm() << ", normals' residual " << rq.tail(m3).norm() << ", update "
                                       << (next - q).norm());
    p_.s = next.head(m3);
    for (Eigen::Index i = 0; i < p_.eps.size(); ++i) {
      const Eigen::Vector3d n = next.segment<3>(m3 + 3 * i);
      p_.n.segment<3>(3 * i) = p_tilde_.eps[i] > 0.0 && p_.eps[i] > 0.0 && n.norm() > 0.5
                                   ? Eigen::Vector3d(n.normalized())
                                   : Eigen::Vector3d(p_tilde_.n.segment<3>(3 * i));
    }
  }
  p_.eps = p_tilde_.eps;
  p_.g0 = p_tilde_.g0;
  c_ = c_tilde_;
}

Eigen::VectorXd Robin::map_derivative(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                                      const Eigen::VectorXd& v) {
  // v moves the planes the beam solved with (p_): the points' part only along the normals, and with
  // the normals as unknowns (next_iterate) their part perpendicular to them
  const Eigen::Index m = p_.eps.size(), m3 = p_.s.size();
  const bool normals = v.size() == 2 * m3;
  std::vector<double> shift(std::size_t(m), 0.0);
  std::vector<participant::Vec3> turn(normals ? std::size_t(m) : 0, {0.0, 0.0, 0.0});
  for (Eigen::Index j = 0; j < m; ++j) {
    if (!(p_.eps[j] > 0.0)) continue;
    const Eigen::Vector3d n = p_.n.segment<3>(3 * j);
    shift[std::size_t(j)] = n.dot(v.segment<3>(3 * j));
    if (!normals) continue;
    const Eigen::Vector3d t = v.segment<3>(m3 + 3 * j) - n.dot(v.segment<3>(m3 + 3 * j)) * n;
    turn[std::size_t(j)] = {t.x(), t.y(), t.z()};
  }
  std::vector<participant::Vec3> dx;
  if (!beam.linear_response(shift, turn, dx).converged || dx.size() != n_) return {};
  std::vector<double> ds;
  std::vector<participant::Vec3> dn;
  if (!solid.linear_response(dx, ds, dn).converged || ds.size() != std::size_t(m) || dn.size() != std::size_t(m))
    return {};
  // The solid's planes (reply_) move by ds along their normals and turn by dn, the points move by dx;
  // the iterate made of them (softened with surface compliance: a function of all three) by forward
  // differences, exact in the points and the shifts where the penalty law is linear.
  double amax = 0.0;
  for (const auto& d : dx) amax = std::max({amax, std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
  for (const auto& d : dn) amax = std::max({amax, std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
  for (double d : ds) amax = std::max(amax, std::abs(d));
  Eigen::VectorXd out = Eigen::VectorXd::Zero(v.size());
  if (!(amax > 0.0)) return out;
  const double h = 1e-6 / amax;
  participant::SamplePoints x1 = x_;
  for (std::size_t i = 0; i < n_; ++i)
    for (int c = 0; c < 3; ++c) x1.x[i][c] += h * dx[i][c];
  Planes r1 = reply_;
  for (Eigen::Index j = 0; j < m; ++j) {
    if (!(reply_.eps[j] > 0.0)) continue;
    const Eigen::Vector3d n = reply_.n.segment<3>(3 * j);
    const std::size_t js = std::size_t(j);
    r1.s.segment<3>(3 * j) += h * ds[js] * n;
    r1.n.segment<3>(3 * j) = (n + h * Eigen::Vector3d(dn[js][0], dn[js][1], dn[js][2])).normalized();
  }
  const Planes t1 = compliance_ ? softened_(x1, r1, plane_forces(x1, r1)) : r1;
  for (Eigen::Index j = 0; j < m; ++j) {
    if (!(p_tilde_.eps[j] > 0.0)) continue;
    const Eigen::Vector3d n = p_tilde_.n.segment<3>(3 * j);
    out.segment<3>(3 * j) = n.dot(t1.s.segment<3>(3 * j) - p_tilde_.s.segment<3>(3 * j)) / h * n;
    if (normals) out.segment<3>(m3 + 3 * j) = (t1.n.segment<3>(3 * j) - n) / h;
  }
  return out;
}

void Robin::reject() {
  if (!compliance_ || !(k_.array() > 0.0).any()) return;
  // The attempt is made again from plain planes: a stiffness estimate from a step in which the
  // contact set changed (a wall coming to rest on the stent) can be far too low, and the beam then
  // overshoots at every iteration of every attempt. Estimates start again from the next step.
  k_.setZero();
  std::fill(softened_last_.begin(), softened_last_.end(), false);  // p_last_ becomes a bare plane
  std::fill(k_surface_.begin(), k_surface_.end(), 0.0);
  p_last_ = accepted_reply_;
  dt_last_ = 0.0;  // no extrapolation between a soft and a plain plane
}

void Robin::accept(double increment) {
  if (compliance_) {
    accepted_reply_ = reply_;
    // the new estimates apply from the accepted state on (the next step's first iterate; c_tilde_
    // stays: the re-softened planes carry the same loads at x_)
    update_stiffness_();
    p_tilde_ = softened_(x_, reply_, f_reply_);
  }
  p_before_ = p_last_;
  softened_before_ = softened_last_;
  for (std::size_t j = 0; j < softened_last_.size(); ++j)
    softened_last_[j] = stiffness_(Eigen::Index(j)) > 0.0;  // never without compliance
  p_last_ = p_tilde_;
  c_last_ = c_tilde_;
  dt_last_ = increment;
}

}  // namespace angio::coupler
