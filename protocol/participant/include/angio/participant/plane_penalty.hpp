// Penalty law of a frozen contact plane at one beam sample point (robin coupling mode, docs/design.md §5.3):
// the solid surface near the point is replaced by its tangent plane (point s, unit normal n
// toward the beam), so the paper's penalty potential Π = ∫ ε/2 ⟨g⟩² ds (Eq. 4) with the gap of
// Eq. 5 linearized to g(x) = (x − s)·n − R gives the line load and its derivative
//   q(x) = −ε ⟨g(x)⟩ n,   dq/dx = −ε n nᵀ if g < 0, else 0.
// With g0 > 0 the C¹ linear-quadratic law of the solid's line contact (penalty_law.hpp, the same
// function): q = ε (g0/2 − g) n for g ≤ 0, ε (g0 − g)²/(2 g0) n for 0 < g < g0.
// Pure function, shared by the beam (which integrates it in its Newton) and the coupler (which
// evaluates the load the beam applied, for the interface residual).
#pragma once

#include <Eigen/Dense>

#include "angio/participant/penalty_law.hpp"

namespace angio::participant {

struct PlanePenalty {
  Eigen::Vector3d q = Eigen::Vector3d::Zero();      // line load on the beam, N/mm
  Eigen::Matrix3d dq_dx = Eigen::Matrix3d::Zero();  // N/mm²
  double gap = 0.0;                                 // mm (negative: penetration)
};

inline PlanePenalty plane_penalty(const Eigen::Vector3d& x, const Eigen::Vector3d& s, const Eigen::Vector3d& n,
                                  double eps, double radius, double g0 = 0.0) {
  PlanePenalty out;
  const double g = out.gap = (x - s).dot(n) - radius;
  if (!(g < g0) || !(eps > 0.0)) return out;  // separated: no load
  const PenaltyLaw law = penalty_law(g, g0, eps);
  out.q = law.f * n;
  out.dq_dx = -law.k * n * n.transpose();
  return out;
}

}  // namespace angio::participant
