// Cross-section constitutive law of the Simo–Reissner beam (paper Appendix C).
// Pure functions: convected strains (Γ, Ω) + committed internal variables → stress resultants
// (F, M), algorithmic tangent, updated internal variables. Units: mm, N, MPa.
#pragma once

#include <Eigen/Dense>

namespace angio::beam {

using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;

struct Section {
  double EA = 0, GA2 = 0, GA3 = 0;  // axial and shear stiffness (N)
  double GJ = 0, EI2 = 0, EI3 = 0;  // torsional and bending stiffness (N mm^2)
  double contact_radius = 0;        // mm, radius used for contact sample points
  // Elasto-plastic bending (Appendix C); only for circular sections (EI2 == EI3).
  bool plastic = false;
  double My0 = 0;  // initial yield moment (N mm)
  double HI = 0;   // hardening modulus times I (N mm^2), H = Eep/(1 - Eep/E)
};

// Circular section of radius R (shear factor 6(1+nu)/(7+6nu) by default, Cowper).
Section circular_section(double E, double nu, double R, double shear_factor = -1.0);
// General section from A, I2, I3, J and shear factors.
Section general_section(double E, double G, double A, double I2, double I3, double J, double k2, double k3);
// Adds Appendix C plasticity: M_y = My0 + H I κ̄, H = Eep / (1 - Eep/E), I = EI/E.
void add_bending_plasticity(Section& s, double E, double My0, double Eep);

// Internal variables of one Gauss point (convected frame).
struct PlasticState {
  Vec3 omega_pl = Vec3::Zero();  // plastic bending curvature (components 2,3 only)
  double kappa_bar = 0.0;        // accumulated plastic bending curvature
};

struct SectionResponse {
  Vec6 stress;         // (F, M) convected
  Mat6 tangent;        // d(stress)/d(strain), algorithmic
  PlasticState state;  // updated internal variables
  bool yielding = false;
  double bending_moment_norm = 0.0;
};

// strain = (Γ, Ω) convected, relative to the stress-free reference.
SectionResponse evaluate_section(const Section& s, const Vec6& strain, const PlasticState& committed);

}  // namespace angio::beam
