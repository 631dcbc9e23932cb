// Two-node geometrically exact Simo–Reissner beam element (Crisfield–Jelenić interpolation).
//
// Nodal triads Λ_a = R_a · O_a (R_a: rotation of the node from its reference state, shared by all
// elements meeting at the node = rigid joint; O_a: constant reference triad of this element at
// node a, e1 along the beam). With φ = log(Λ1ᵀΛ2) the reference rotation is
// Λ_r = Λ1 exp(φ/2) and, with one-point (reduced) integration at the midpoint,
//   Ω = φ/L − Ω0,    Γ = Λ_rᵀ (x2 − x1)/L − E1 − Γ0,
// which is objective, path independent and free of shear locking.
// The tangent is the exact linearization of the residual with respect to the spatial
// multiplicative rotation increments (Λ ← exp(Δθ) Λ) and the displacement increments, obtained
// with nested forward-mode automatic differentiation (dual.hpp).
// Two variational forms share the strains and the section law (ResidualForm): the consistent
// variation of the strain energy (default) and 4C's Petrov–Galerkin form (beam3r, Jelenić &
// Crisfield 1999), which tests the rotational equations with the Lagrange shape functions.
// DOF order: [x1 (3), θ1 (3), x2 (3), θ2 (3)].
#pragma once

#include <Eigen/Geometry>

#include "angio/beam/material.hpp"

namespace angio::beam {

using Quat = Eigen::Quaterniond;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

struct ElementReference {
  double L0 = 0;
  Quat O1 = Quat::Identity(), O2 = Quat::Identity();
  Vec3 Gamma0 = Vec3::Zero(), Omega0 = Vec3::Zero();
};

// Builds the reference data; O1, O2 are the element's reference triads at its two nodes.
ElementReference make_element_reference(const Vec3& X1, const Vec3& X2, const Quat& O1, const Quat& O2);
// Triad with e1 along (X2 − X1) and e2 as close as possible to `up`.
Quat triad_from_tangent(const Vec3& t, const Vec3& up);

// Convected strains (Γ, Ω) of the current configuration.
Vec6 element_strain(const ElementReference& ref, const Vec3& x1, const Vec3& x2, const Quat& R1, const Quat& R2);

struct ElementResult {
  Vec12 residual;  // internal forces and moments (spatial), N and N mm
  Mat12 tangent;
  Vec6 strain;
  SectionResponse section;
};

// Variational form of the element residual (scene key stent.element.residual).
//  consistent       r = L Bᵀ(F, M), B = ∂(Γ, Ω)/∂(δx, δθ): Bubnov–Galerkin, the exact variation
//                   of the strain energy; the rotational test functions are Jelenić–Crisfield's
//                   generalized shape functions Ĩ (δθ_r and δφ = J⁻¹(φ)Λ1ᵀ(δθ2 − δθ1)).
//  petrov_galerkin  4C beam3r (Jelenić & Crisfield 1999: weak form tested with the Lagrange
//                   functions I_a for δx and δθ): with n = Λ_r F, m = Λ_r M, d = x2 − x1 at the
//                   single (midpoint) Gauss point, where I_a = ½ and I_a' = ∓1/L,
//                     r_x1 = −n, r_θ1 = −m − ½ d×n,  r_x2 = n, r_θ2 = m − ½ d×n.
//                   Non-symmetric tangent even at equilibrium (needs an LU solver; all of
//                   linear_solver.hpp's backends are LU). Equal to the consistent form when
//                   M ∥ φ and d×n ∥ Λ_r φ (e.g. planar bending, or elastic GJ = EI without
//                   shear); otherwise the rotational residuals differ by O(φ) relative in the
//                   d×n term and O(φ²) in the moment term (φ: relative rotation of the element).
enum class ResidualForm { consistent, petrov_galerkin };

ElementResult evaluate_element(const Section& s, const ElementReference& ref, const Vec3& x1, const Vec3& x2,
                               const Quat& R1, const Quat& R2, const PlasticState& committed, bool with_tangent = true,
                               ResidualForm form = ResidualForm::consistent);

// Rotation helpers.
Quat quat_exp(const Vec3& theta);  // exp of a rotation vector
Vec3 quat_log(const Quat& q);      // rotation vector (|θ| <= π)

}  // namespace angio::beam
