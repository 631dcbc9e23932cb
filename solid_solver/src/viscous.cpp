#include "angio/solid/viscous.hpp"

#include <cmath>

namespace angio::solid {

double viscous_rate_factor(double xi) {
  if (xi < 1e-8) return 1.0 - 0.5 * xi;  // series: 1 − ξ/2 + ξ²/6 − …
  return -std::expm1(-xi) / xi;
}

Vec6 viscous_update(const ViscousBranch& v, double dt, const Vec6& Q_n, const Vec6& S_inf_n, const Vec6& S_inf,
                    double* tangent_factor) {
  const double xi = dt / v.tau;
  const double g = viscous_rate_factor(xi);
  if (tangent_factor) *tangent_factor = 1.0 + v.beta * g;
  return std::exp(-xi) * Q_n + (v.beta * g) * (S_inf - S_inf_n);
}

}  // namespace angio::solid
