#include "angio/coupler/robin.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "angio/common/log.hpp"
#include "angio/participant/plane_penalty.hpp"
#include "interface_vectors.hpp"

namespace angio::coupler {

Robin::Robin(std::size_t n) : n_(n) {
  set_planes_per_point_(1);
  c_ = c_tilde_ = c_last_ = Eigen::VectorXd::Zero(3 * n);
}

void Robin::set_planes_per_point_(std::size_t K) {
  K_ = K;
  p_.s = p_.n = Eigen::VectorXd::Zero(3 * K * n_);
  p_.eps = Eigen::VectorXd::Zero(K * n_);  // no planes before the solid has answered once
  p_tilde_ = p_last_ = p_before_ = p_;
}

void Robin::begin_step(double increment, bool extrapolate) {
  p_ = p_last_;
  c_ = c_last_;
  if (!(extrapolate && dt_last_ > 0.0)) return;
  const double f = increment / dt_last_;
  for (Eigen::Index i = 0; i < p_.eps.size(); ++i)
    if (p_last_.eps[i] > 0.0 && p_before_.eps[i] > 0.0) {
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

Eigen::VectorXd Robin::plane_loads(const participant::SamplePoints& x, const Planes& p) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3 * x.size());
  const std::size_t K = std::size_t(p.eps.size()) / x.size();
  for (Eigen::Index j = 0; j < p.eps.size(); ++j) {
    if (!(p.eps[j] > 0.0)) continue;
    const std::size_t i = std::size_t(j) / K;
    const Eigen::Vector3d xi(x.x[i][0], x.x[i][1], x.x[i][2]);
    q.segment<3>(3 * i) +=
        participant::plane_penalty(xi, p.s.segment<3>(3 * j), p.n.segment<3>(3 * j), p.eps[j], x.radius[i], p.g0).q;
  }
  return q;
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
  const Eigen::VectorXd q_beam = c_ + plane_loads(x, p_);  // what the beam applied at x
  p_tilde_.s = flatten(reply.surface_points);
  p_tilde_.n = flatten(reply.normals);
  p_tilde_.g0 = reply.regularization;
  p_tilde_.eps = Eigen::Map<const Eigen::VectorXd>(reply.penalty.data(), Eigen::Index(reply.penalty.size()));
  c_tilde_ = q_tilde - plane_loads(x, p_tilde_);
  return q_tilde - q_beam;
}

void Robin::next_iterate(Acceleration& acc, int k) {
  // Residual of the plane points along the new normals; points without a plane now keep their
  // point (residual 0), points that just got one take it as it is.
  Eigen::VectorXd r = Eigen::VectorXd::Zero(p_.s.size());
  for (Eigen::Index i = 0; i < p_.eps.size(); ++i) {
    if (!(p_tilde_.eps[i] > 0.0)) continue;
    // (not an evaluation of the map: the secant pair of this iteration is inconsistent for these
    // points, and IQN-ILS may see a zero model step later; its stagnation restart handles that)
    if (!(p_.eps[i] > 0.0)) p_.s.segment<3>(3 * i) = p_tilde_.s.segment<3>(3 * i);
    const Eigen::Vector3d n = p_tilde_.n.segment<3>(3 * i);
    r.segment<3>(3 * i) = n.dot(p_tilde_.s.segment<3>(3 * i) - p_.s.segment<3>(3 * i)) * n;
  }
  Eigen::VectorXd next = acc.update(p_.s, r, k);
  LOG_DEBUG("robin: plane residual " << r.norm() << ", update " << (next - p_.s).norm());
  p_.s = std::move(next);
  p_.n = p_tilde_.n;
  p_.eps = p_tilde_.eps;
  p_.g0 = p_tilde_.g0;
  c_ = c_tilde_;
}

void Robin::accept(double increment) {
  p_before_ = p_last_;
  p_last_ = p_tilde_;
  c_last_ = c_tilde_;
  dt_last_ = increment;
}

}  // namespace angio::coupler
