// Pure constitutive kernels for the solid solver (no MPI, no PETSc).
// Units: mm, N, MPa. Voigt order for symmetric tensors: 11, 22, 33, 12, 23, 13; strain-like
// Voigt vectors use engineering shear (2 E12), so that dS_voigt = D dE_voigt with D = 2 dS/dC.
#pragma once
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "angio/scene/keys_generated.hpp"

namespace angio::solid {

using Mat3 = Eigen::Matrix3d;
using Vec3d = Eigen::Vector3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

inline constexpr int kVoigt[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

Vec6 to_voigt_stress(const Mat3& S);
Mat3 from_voigt_stress(const Vec6& s);

// Compressible Neo-Hooke (4C "coupled Neo-Hooke"):
//   Psi = mu/2 (I1 - 3) + mu/(2 beta) (J^(-2 beta) - 1), mu = E/(2(1+nu)), beta = nu/(1-2nu)
//   (beta = 0: volumetric term -mu ln J).
//   S = mu (I - J^(-2beta) C^-1),  D = 2 mu beta J^(-2beta) C^-1 (x) C^-1 + 2 mu J^(-2beta) I_{C^-1}
struct NeoHooke {
  double E = 1.0;
  double nu = 0.0;
  double mu() const { return E / (2.0 * (1.0 + nu)); }
  double beta() const { return nu / (1.0 - 2.0 * nu); }
};
double energy(const NeoHooke& m, const Mat3& C);
// Adds S and D (D may be null).
void add_stress(const NeoHooke& m, const Mat3& C, Mat3& S, Mat6* D);

// One exponential fiber family (Holzapfel-Gasser-Ogden without dispersion, paper eq. B.4):
//   Psi = k1/(2 k2) (exp(k2 (I4 - 1)^2) - 1),   I4 = a0 . C a0 (|a0| = 1),
// by default in tension only (Psi = 0 for I4 <= 1, docs/design.md §7.3, as fibers buckle); tension_only =
// false keeps it for I4 < 1 too, as eq. B.4 is printed (an "artificial" balloon fiber that resists
// axial compression and hence bending).
struct FiberFamily {
  double k1 = 0.0;
  double k2 = 0.0;
  Vec3d a0 = Vec3d::UnitX();
  bool tension_only = true;
};
double energy(const FiberFamily& f, const Mat3& C);
void add_stress(const FiberFamily& f, const Mat3& C, Mat3& S, Mat6* D);

// Fiber family specification relative to a local frame (circumferential e_c, axial e_a, radial
// e_r): direction a0 = cos(phi) e_c + sin(phi) e_a, phi in degrees from circumferential toward
// axial. `pair` adds the mirrored family at -phi (two families as in the paper's appendix B).
struct FiberSpec {
  double k1 = 0.0;
  double k2 = 0.0;
  double angle_deg = 0.0;
  bool pair = false;
  bool tension_only = true;
};

// Part of the hyperelastic stress S∞ that drives the viscous branch (scene `viscous.acts_on`):
//   isotropic – the Neo-Hooke matrix alone (Ψ_iso, eq. B.2, with its volumetric term); the fiber
//               stress (eq. B.4) is added after the overstress is formed and never relaxes. This is
//               4C's placement (MAT_ViscoElastHyper with VISCO_GenMax, src/mat/4C_mat_viscoelasthyper.cpp,
//               ViscoElastHyper::evaluate: the isotropic summands, then evaluate_visco_gen_max on
//               that stress, then the anisotropic summands), the code the paper was computed with.
//   all       – the whole S∞ = S_iso + S_fibers (eqs. B.7–B.8 read literally).
enum class ViscousActsOn { isotropic, all };
inline constexpr ViscousActsOn kViscousActsOnDefault =  // 4C's placement (core/scene/keys.yaml)
    std::string_view(scene::keys::defaults::artery_layers_viscous_acts_on) == "isotropic" ? ViscousActsOn::isotropic
                                                                                          : ViscousActsOn::all;
inline const char* to_string(ViscousActsOn a) { return a == ViscousActsOn::isotropic ? "isotropic" : "all"; }

// Parameters of the viscous branch of a layer (paper eqs. B.5–B.8; kernel in viscous.hpp).
struct ViscousBranch {
  double tau = 0.5;   // relaxation time (s), > 0
  double beta = 0.3;  // ratio of the viscoelastic to the hyperelastic branch, ≥ 0
  ViscousActsOn acts_on = kViscousActsOnDefault;
};

// A layer / block material: Neo-Hooke ground matrix plus fiber families, optionally a viscous branch.
struct LayerMaterial {
  std::string name;
  NeoHooke matrix;
  std::vector<FiberSpec> fibers;
  std::optional<ViscousBranch> viscous = std::nullopt;  // none: purely hyperelastic
};

// Local material frame of an element.
struct Frame {
  Vec3d circumferential = Vec3d::UnitX();
  Vec3d axial = Vec3d::UnitZ();
  Vec3d radial = Vec3d::UnitY();
};

// Concrete fiber families of one element (directions resolved from the frame).
std::vector<FiberFamily> resolve_fibers(const LayerMaterial& m, const Frame& frame);

// Total energy, stress and tangent of a layer material at a material point with resolved fibers.
double energy(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const Mat3& C);
void stress_tangent(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const Mat3& C, Mat3& S, Mat6* D);

// First principal Cauchy stress and its direction from F and S (sigma = F S F^T / J).
void first_principal_cauchy(const Mat3& F, const Mat3& S, double& s1, Vec3d& dir);

}  // namespace angio::solid
