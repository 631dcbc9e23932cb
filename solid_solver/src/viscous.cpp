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

void viscous_stress_tangent(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const ViscousBranch& v,
                            double dt, const Vec6& Q_n, const Vec6& Sv_n, const Mat3& C, Mat3& S, Mat6* D, Vec6& Q,
                            Vec6& Sv) {
  const bool fibers_relax = v.acts_on == ViscousActsOn::all;
  S.setZero();
  if (D) D->setZero();
  add_stress(m, C, S, D);
  if (fibers_relax)
    for (const auto& f : fibers) add_stress(f, C, S, D);
  Sv = to_voigt_stress(S);
  double factor = 1.0;
  Q = viscous_update(v, dt, Q_n, Sv_n, Sv, &factor);
  S += from_voigt_stress(Q);
  if (D) *D *= factor;  // (1 + β g) dSv/dE
  if (!fibers_relax)    // 4C: the anisotropic summands come after the overstress
    for (const auto& f : fibers) add_stress(f, C, S, D);
}

}  // namespace angio::solid
