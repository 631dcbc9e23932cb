#include "angio/beam/material.hpp"

#include <cmath>
#include <stdexcept>

namespace angio::beam {

Section circular_section(double E, double nu, double R, double shear_factor) {
  const double G = E / (2.0 * (1.0 + nu));
  const double A = M_PI * R * R;
  const double I = M_PI * R * R * R * R / 4.0;
  const double k = shear_factor > 0 ? shear_factor : 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
  Section s = general_section(E, G, A, I, I, 2.0 * I, k, k);
  s.contact_radius = R;
  return s;
}

Section general_section(double E, double G, double A, double I2, double I3, double J, double k2, double k3) {
  Section s;
  s.EA = E * A;
  s.GA2 = G * k2 * A;
  s.GA3 = G * k3 * A;
  s.GJ = G * J;
  s.EI2 = E * I2;
  s.EI3 = E * I3;
  s.contact_radius = std::sqrt(A / M_PI);
  return s;
}

void add_bending_plasticity(Section& s, double E, double My0, double Eep) {
  if (std::abs(s.EI2 - s.EI3) > 1e-12 * s.EI2)
    throw std::invalid_argument("bending plasticity needs a circular section (I2 == I3)");
  if (!(Eep < E)) throw std::invalid_argument("plastic tangent modulus must be below E");
  const double H = Eep / (1.0 - Eep / E);
  const double I = s.EI2 / E;
  s.plastic = true;
  s.My0 = My0;
  s.HI = H * I;
}

SectionResponse evaluate_section(const Section& s, const Vec6& strain, const PlasticState& committed) {
  SectionResponse r;
  r.tangent.setZero();
  r.tangent(0, 0) = s.EA;
  r.tangent(1, 1) = s.GA2;
  r.tangent(2, 2) = s.GA3;
  r.tangent(3, 3) = s.GJ;
  r.tangent(4, 4) = s.EI2;
  r.tangent(5, 5) = s.EI3;
  r.state = committed;
  if (!s.plastic) {
    r.stress = r.tangent * strain;
    r.bending_moment_norm = std::hypot(r.stress(4), r.stress(5));
    return r;
  }
  // Appendix C: torsion elastic, bending elasto-plastic with linear isotropic hardening.
  const double EI = s.EI2;
  r.stress.head<4>() = r.tangent.topLeftCorner<4, 4>() * strain.head<4>();
  Eigen::Vector2d kb(strain(4), strain(5));
  Eigen::Vector2d kp(committed.omega_pl(1), committed.omega_pl(2));
  Eigen::Vector2d Mtr = EI * (kb - kp);
  const double nMtr = Mtr.norm();
  const double My = s.My0 + s.HI * committed.kappa_bar;
  const double phi = nMtr - My;
  if (phi <= 0.0 || nMtr == 0.0) {
    r.stress.tail<2>() = Mtr;
    r.bending_moment_norm = nMtr;
    return r;
  }
  // Radial return.
  const double dgamma = phi / (EI + s.HI);
  const Eigen::Vector2d n = Mtr / nMtr;
  const double Mnorm = nMtr - EI * dgamma;
  r.stress.tail<2>() = Mnorm * n;
  r.state.omega_pl(1) += dgamma * n(0);
  r.state.omega_pl(2) += dgamma * n(1);
  r.state.kappa_bar += dgamma;
  r.yielding = true;
  r.bending_moment_norm = Mnorm;
  // Consistent tangent: EI [ HI/(EI+HI) n n^T + (Mnorm/|Mtr|)(I - n n^T) ].
  const Eigen::Matrix2d nn = n * n.transpose();
  const Eigen::Matrix2d Cb = EI * (s.HI / (EI + s.HI) * nn + (Mnorm / nMtr) * (Eigen::Matrix2d::Identity() - nn));
  r.tangent.bottomRightCorner<2, 2>() = Cb;
  return r;
}

}  // namespace angio::beam
