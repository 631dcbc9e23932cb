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
ElementReference make_element_reference(const Vec3& X1, const Vec3& X2, const Quat& O1,
                                         const Quat& O2);
// Triad with e1 along (X2 − X1) and e2 as close as possible to `up`.
Quat triad_from_tangent(const Vec3& t, const Vec3& up);

// Convected strains (Γ, Ω) of the current configuration.
Vec6 element_strain(const ElementReference& ref, const Vec3& x1, const Vec3& x2, const Quat& R1,
                    const Quat& R2);

struct ElementResult {
  Vec12 residual;  // internal forces and moments (spatial), N and N mm
  Mat12 tangent;
  Vec6 strain;
  SectionResponse section;
};

ElementResult evaluate_element(const Section& s, const ElementReference& ref, const Vec3& x1,
                               const Vec3& x2, const Quat& R1, const Quat& R2,
                               const PlasticState& committed, bool with_tangent = true);

// Rotation helpers.
Quat quat_exp(const Vec3& theta);   // exp of a rotation vector
Vec3 quat_log(const Quat& q);       // rotation vector (|θ| <= π)

}  // namespace angio::beam
