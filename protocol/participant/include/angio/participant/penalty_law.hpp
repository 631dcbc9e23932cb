// The penalty law of the stent's line contact, one implementation for the solid's line contact
// (solid_solver/contact line_contact.cpp) and the frozen contact planes of the robin coupling
// (plane_penalty.hpp): the paper's penalty potential Π = ∫ ε/2 ⟨g⟩² ds (Eq. 4) per unit length at
// gap g, or with a regularization g0 > 0 its C¹ linear-quadratic variant (force zero at g = g0,
// quadratic in between, linear for g ≤ 0; the g0 → 0 limit is the linear law).
#pragma once

#include <cmath>

namespace angio::participant {

// At gap g (mm) of an active point (g < g0): potential pi (N), force magnitude f = −dpi/dg (N/mm,
// pushing the surfaces apart) and its stiffness k = −df/dg (N/mm²), for penalty eps (N/mm²).
struct PenaltyLaw {
  double pi, f, k;
};

inline PenaltyLaw penalty_law(double g, double g0, double eps) {
  if (g0 <= 0.0) return {0.5 * eps * g * g, -eps * g, eps};
  if (g <= 0.0) return {eps * (0.5 * g * g - 0.5 * g0 * g + g0 * g0 / 6.0), eps * (0.5 * g0 - g), eps};
  return {eps * (g0 - g) * (g0 - g) * (g0 - g) / (6.0 * g0), 0.5 * eps * (g0 - g) * (g0 - g) / g0, eps * (g0 - g) / g0};
}

// The inverse: the gap (mm) at which penalty_law gives the force f > 0 (N/mm); g0 for f <= 0
// (the edge of contact). Used to place a plane that carries a given load with another penalty.
inline double penalty_gap(double f, double g0, double eps) {
  if (!(f > 0.0)) return g0 > 0.0 ? g0 : 0.0;
  if (g0 <= 0.0) return -f / eps;
  if (f >= 0.5 * eps * g0) return 0.5 * g0 - f / eps;
  return g0 - std::sqrt(2.0 * g0 * f / eps);
}

}  // namespace angio::participant
