#include "angio/solid/viscous.hpp"

#include <cmath>

namespace angio::solid {

double viscous_rate_factor(double xi) {
  return xi == 0.0 ? 1.0 : -std::expm1(-xi) / xi;  // expm1: no cancellation for small ξ
}

Vec6 viscous_update(const ViscousBranch& v, double dt, const Vec6& Q_n, const Vec6& S_inf_n, const Vec6& S_inf,
                    double* tangent_factor) {
  const double xi = dt / v.tau;
  const double g = viscous_rate_factor(xi);
  if (tangent_factor) *tangent_factor = 1.0 + v.beta * g;
  return std::exp(-xi) * Q_n + (v.beta * g) * (S_inf - S_inf_n);
}

}  // namespace angio::solid
