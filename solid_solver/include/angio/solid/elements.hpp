// Finite element kernels (pure functions, no MPI/PETSc): shape functions, quadrature,
// total-Lagrangian internal force/tangent, follower pressure and spring faces.
// Node orderings follow gmsh (hex8, tet4, tet10: edges 01 12 20 30 32 31; tri6: 01 12 20).
#pragma once
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "angio/contact/face.hpp"
#include "angio/solid/materials.hpp"
#include "angio/solid/viscous.hpp"

namespace angio::solid {

enum class ElemType { Hex8, Tet4, Tet10 };
enum class FaceType { Quad4, Tri3, Tri6 };

// The same face as a contact face kind (the face shape functions live in angio::contact).
inline contact::FaceKind to_contact(FaceType t) {
  static_assert(int(FaceType::Quad4) == int(contact::FaceKind::Quad4) &&
                int(FaceType::Tri3) == int(contact::FaceKind::Tri3) &&
                int(FaceType::Tri6) == int(contact::FaceKind::Tri6));
  return contact::FaceKind(int(t));
}

constexpr int num_nodes(ElemType t) {
  switch (t) {
    case ElemType::Hex8:
      return 8;
    case ElemType::Tet4:
      return 4;
    case ElemType::Tet10:
      return 10;
  }
  return 0;
}
int num_nodes(FaceType t);
int num_corners(FaceType t);
const char* name(ElemType t);
const char* name(FaceType t);

struct QuadPoint {
  double xi[3];
  double w;
};
// Full integration: hex8 2x2x2, tet4 1 point, tet10 4 points (degree 2).
const std::vector<QuadPoint>& volume_rule(ElemType t);
// quad4 2x2, tri3 3 points, tri6 6 points (degree 4).
const std::vector<QuadPoint>& face_rule(FaceType t);

// N (n) and dN/dxi (n x 3) at a reference point.
void shape(ElemType t, const double* xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN);
// N (n) and dN/dxi (n x 2) on a face.
void shape(FaceType t, const double* xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN);
// Reference coordinates of the element's nodes (for tests and stress recovery).
std::vector<Vec3d> reference_nodes(ElemType t);
// Local faces of a volume element (node index lists, face type).
struct LocalFace {
  FaceType type;
  std::vector<int> nodes;
};
const std::vector<LocalFace>& local_faces(ElemType t);

// Internal force vector f (3n) and tangent K (3n x 3n) of one element in total-Lagrangian form:
//   f_a = int B_a^T S dV,  K = int B^T D B + (grad N_a . S grad N_b) I dV.
// X, u: n x 3 (reference coordinates and displacements). K may be null (residual only).
// Returns false if a Jacobian (reference or deformed) is non-positive.
// visc (optional): the viscous branch of the element's material with its committed Gauss-point
// history (viscous.hpp); S = S∞ + Q and the tangent dS∞/dE + β g dSv/dE (viscous_stress_tangent;
// Sv = the isotropic Neo-Hooke stress or all of S∞, ViscousBranch::acts_on). With visc->Q_out/S_out set
// the updated history is stored there (SolidModel::commit).
struct ElementStress {
  Mat3 cauchy_avg = Mat3::Zero();  // Gauss-point average of the Cauchy stress
  double energy = 0.0;             // int Psi dV
  double volume = 0.0;             // reference volume
  // Cauchy stress at each Gauss point, volume_rule(t) order (the first volume_rule(t).size() entries;
  // stress recovery, recovery_kernels.hpp)
  std::array<Mat3, 8> cauchy_qp;
};
bool element_internal(ElemType t, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u, const NeoHooke& mat,
                      const std::vector<FiberFamily>& fibers, Eigen::VectorXd& f, Eigen::MatrixXd* K,
                      ElementStress* out = nullptr, const ViscousHistory* visc = nullptr);

// Follower pressure p on a face (traction -p n da, n = normal of the face orientation, i.e.
// outward for oriented faces): contribution to the residual r = f_int - f_ext is
//   r_a = + p int N_a (x_,xi x x_,eta) dxi deta and its consistent tangent dr/dx.
void face_pressure(FaceType t, const Eigen::MatrixXd& x, double p, Eigen::VectorXd& r, Eigen::MatrixXd* K);
// Omnidirectional springs per unit reference area k (N/mm^3): r_a = k int N_a N_b dA u_b.
void face_springs(FaceType t, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u, double k, Eigen::VectorXd& r,
                  Eigen::MatrixXd* K);
// Area vector int (X_,xi x X_,eta) dxi deta and centroid of a face (reference geometry).
Vec3d face_area_vector(FaceType t, const Eigen::MatrixXd& X);

}  // namespace angio::solid
