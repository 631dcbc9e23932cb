// Element kernel of the nodal stress recovery (recovery_kernels.hpp), alone: quadrature, element
// mass matrix, and the one-element projection of constant and linear Gauss-point stress fields.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "angio/solid/recovery_kernels.hpp"

using namespace angio::solid;

namespace {

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// Node positions (rows) of one element of type t: the reference nodes mapped by an affine map,
// plus (perturb > 0) a random displacement of every node (hex8) or of the mid-edge nodes (tet10:
// curved edges).
Eigen::MatrixXd element_nodes(ElemType t, double perturb, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-perturb, perturb);
  Mat3 A;
  A << 0.9, 0.2, -0.1, 0.05, 1.1, 0.15, -0.2, 0.1, 0.8;
  const Vec3d c(0.3, -0.2, 1.5);
  const auto ref = reference_nodes(t);
  Eigen::MatrixXd X(ref.size(), 3);
  for (size_t a = 0; a < ref.size(); ++a) {
    Vec3d x = A * ref[a] + c;
    if (perturb > 0 && (t == ElemType::Hex8 || a >= 4)) x += Vec3d(U(rng), U(rng), U(rng));
    X.row(a) = x.transpose();
  }
  return X;
}

Mat3 random_symmetric(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Mat3 s;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) s(i, j) = s(j, i) = U(rng);
  return s;
}

// The nodal tensors of a one-element projection: M s = b.
std::vector<Mat3> project_one(ElemType t, const Eigen::MatrixXd& X, const std::vector<Mat3>& gauss) {
  Eigen::MatrixXd M, b;
  recovery_element(t, X, gauss.data(), &M, &b);
  const Eigen::MatrixXd s = M.ldlt().solve(b);
  std::vector<Mat3> out(X.rows());
  for (int a = 0; a < X.rows(); ++a)
    for (int k = 0; k < 6; ++k) out[a](kVoigt[k][0], kVoigt[k][1]) = out[a](kVoigt[k][1], kVoigt[k][0]) = s(a, k);
  return out;
}

// Reference position of the Gauss point q of the element (isoparametric map).
Vec3d gauss_position(ElemType t, const Eigen::MatrixXd& X, int q) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  shape(t, volume_rule(t)[q].xi, N, dN);
  return X.transpose() * N;
}

}  // namespace

// The tet rules integrate the monomials x^i y^j z^k over the unit tetrahedron exactly up to their
// degree (tet10: 5, tet4: 2): ∫ = i! j! k! / (i + j + k + 3)!.
TEST(RecoveryKernel, TetRulesIntegrateMonomialsExactly) {
  for (auto [t, degree] : {std::pair{ElemType::Tet10, 5}, std::pair{ElemType::Tet4, 2}}) {
    const auto& rule = recovery_rule(t);
    for (const auto& qp : rule) EXPECT_GT(qp.w, 0.0);
    for (int i = 0; i <= degree; ++i)
      for (int j = 0; i + j <= degree; ++j)
        for (int k = 0; i + j + k <= degree; ++k) {
          double sum = 0.0;
          for (const auto& qp : rule)
            sum += qp.w * std::pow(qp.xi[0], i) * std::pow(qp.xi[1], j) * std::pow(qp.xi[2], k);
          const double exact = factorial(i) * factorial(j) * factorial(k) / factorial(i + j + k + 3);
          EXPECT_NEAR(sum, exact, 1e-15) << name(t) << " x^" << i << " y^" << j << " z^" << k;
        }
  }
}

// The element mass matrix is symmetric positive definite and its entries sum to the element volume,
// on distorted hex8 and curved tet10 elements too.
TEST(RecoveryKernel, MassMatrixIsSymmetricPositiveAndSumsToTheVolume) {
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10})
    for (double perturb : {0.0, 0.08}) {
      const Eigen::MatrixXd X = element_nodes(t, perturb, 3);
      Eigen::MatrixXd M;
      const double V = recovery_element(t, X, nullptr, &M, nullptr);
      EXPECT_GT(V, 0.0);
      EXPECT_LT((M - M.transpose()).norm(), 1e-15 * M.norm()) << name(t);
      EXPECT_NEAR(M.sum(), V, 1e-13 * V) << name(t);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 1e-6 * V) << name(t);
      // the element volume of the isoparametric map (the volume rule is exact for it except on curved
      // tet10, whose cubic det J the 4-point rule misses and the 14-point one does not)
      if (t == ElemType::Tet10 && perturb > 0) continue;
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      double Vq = 0.0;
      for (const auto& qp : volume_rule(t)) {
        shape(t, qp.xi, N, dN);
        Vq += qp.w * (X.transpose() * dN).determinant();
      }
      EXPECT_NEAR(V, Vq, 1e-12 * V) << name(t) << " perturb " << perturb;
    }
}

// Patch test of the kernel: the same tensor at every Gauss point is recovered exactly at every node
// of one element of any shape (M and b share the quadrature, M·1 = ∫ N_a dV).
TEST(RecoveryKernel, ConstantStressIsRecoveredExactly) {
  std::mt19937 rng(7);
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10})
    for (double perturb : {0.0, 0.08}) {
      const Mat3 s = random_symmetric(rng);
      const Eigen::MatrixXd X = element_nodes(t, perturb, 11);
      const std::vector<Mat3> gauss(volume_rule(t).size(), s);
      for (const Mat3& r : project_one(t, X, gauss)) EXPECT_LT((r - s).norm(), 1e-12) << name(t);
    }
}

// A stress field linear in the position, sampled at the Gauss points, is recovered exactly at the
// nodes of an affine hex8 or tet10 element (its Gauss-point interpolant is that linear field, which
// the nodal interpolation contains): the projection extrapolates a gradient to the surface. The
// element average is the value at the centroid, off by the gradient times the distance.
TEST(RecoveryKernel, LinearStressIsRecoveredExactlyInAffineElements) {
  std::mt19937 rng(5);
  const Mat3 s0 = random_symmetric(rng);
  const Mat3 g[3] = {random_symmetric(rng), random_symmetric(rng), random_symmetric(rng)};
  auto field = [&](const Vec3d& x) { return Mat3(s0 + x(0) * g[0] + x(1) * g[1] + x(2) * g[2]); };
  for (ElemType t : {ElemType::Hex8, ElemType::Tet10}) {
    const Eigen::MatrixXd X = element_nodes(t, 0.0, 1);
    std::vector<Mat3> gauss;
    for (size_t q = 0; q < volume_rule(t).size(); ++q) gauss.push_back(field(gauss_position(t, X, int(q))));
    const auto r = project_one(t, X, gauss);
    for (int a = 0; a < X.rows(); ++a)
      EXPECT_LT((r[a] - field(X.row(a).transpose())).norm(), 1e-12) << name(t) << " node " << a;
  }
}

// The right-hand side is linear in the Gauss-point values and is not computed without them.
TEST(RecoveryKernel, RightHandSideIsLinearInTheGaussValues) {
  std::mt19937 rng(9);
  const ElemType t = ElemType::Hex8;
  const Eigen::MatrixXd X = element_nodes(t, 0.05, 2);
  std::vector<Mat3> g1, g2, g12;
  for (size_t q = 0; q < 8; ++q) {
    g1.push_back(random_symmetric(rng));
    g2.push_back(random_symmetric(rng));
    g12.push_back(2.0 * g1.back() - 3.0 * g2.back());
  }
  Eigen::MatrixXd b1, b2, b12;
  recovery_element(t, X, g1.data(), nullptr, &b1);
  recovery_element(t, X, g2.data(), nullptr, &b2);
  recovery_element(t, X, g12.data(), nullptr, &b12);
  EXPECT_EQ(b1.rows(), 8);
  EXPECT_EQ(b1.cols(), 6);
  EXPECT_LT((b12 - (2.0 * b1 - 3.0 * b2)).norm(), 1e-14 * b12.norm());
}
