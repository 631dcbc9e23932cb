// Element kernels of the nodal stress recovery (pure functions, no MPI/PETSc; the distributed
// projection is stress_recovery.hpp).
//
// The recovered nodal stress of a block (layer) is the L2 projection of the Gauss-point Cauchy
// stress onto the nodal interpolation of that block alone: find σ_a (per node of the block) with
//   Σ_b M_ab σ_b = b_a,   M_ab = ∫ N_a N_b dV,   b_a = ∫ N_a σ_h dV,
// integrated over the block's elements in the reference configuration (M is constant over a run).
// σ_h is the interpolant of an element's Gauss-point values (volume_rule order): hex8 trilinear
// through its 2×2×2 points, tet10 linear through its 4 points, tet4 the constant of its single
// point. M and b use the same quadrature (recovery_rule), so M·1 = ∫ N_a dV is what b is for a unit
// constant field: a constant stress is recovered exactly on elements of any shape (patch test).
#pragma once
#include <Eigen/Dense>
#include <vector>

#include "angio/solid/elements.hpp"

namespace angio::solid {

// Quadrature of the recovery integrals on the reference element: hex8 its 2×2×2 Gauss rule (=
// volume_rule, where σ_h takes the Gauss-point values themselves), tet4 4 points (degree 2, exact
// for N_a N_b of a straight tet4), tet10 14 points with positive weights (degree 5; the 4-point
// volume rule would make the tet10 element matrix singular).
const std::vector<QuadPoint>& recovery_rule(ElemType t);

// Element contribution (reference coordinates X: n × 3 rows of node positions):
//   M (n × n) = ∫ N_a N_b dV          (if M is non-null)
//   b (n × 6) = ∫ N_a σ_h dV, columns the Voigt components 11, 22, 33, 12, 23, 13 (kVoigt)
//               (if b and gauss_stress are non-null; gauss_stress: volume_rule(t).size() tensors)
// Returns the element's reference volume.
double recovery_element(ElemType t, const Eigen::MatrixXd& X, const Mat3* gauss_stress, Eigen::MatrixXd* M,
                        Eigen::MatrixXd* b);

}  // namespace angio::solid
