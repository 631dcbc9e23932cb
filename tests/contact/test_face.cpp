// Face kernels: shape functions, derivatives, normals, quadrature, bounding boxes.
#include <gtest/gtest.h>

#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

namespace {
const FaceKind kAll[] = {FaceKind::Quad4, FaceKind::Tri3, FaceKind::Tri6};
}

// Compares against: partition of unity (sum N = 1, sum dN = 0) and the Kronecker property at the nodes.
TEST(Face, ShapePartitionOfUnityAndKronecker) {
  for (FaceKind k : kAll) {
    ShapeN N;
    ShapeD dN;
    ShapeDD ddN;
    shape(k, Vec2(0.21, 0.33), N, &dN, &ddN);
    EXPECT_NEAR(N.sum(), 1.0, 1e-14) << name(k);
    EXPECT_NEAR(dN.col(0).sum(), 0.0, 1e-14);
    EXPECT_NEAR(dN.col(1).sum(), 0.0, 1e-14);
    EXPECT_NEAR(ddN.sum(), 0.0, 1e-13);
    for (int c = 0; c < num_corners(k); ++c) {
      shape(k, corner_xi(k, c), N);
      for (int a = 0; a < num_nodes(k); ++a) EXPECT_NEAR(N(a), a == c ? 1.0 : 0.0, 1e-14);
    }
  }
  // tri6 mid-edge nodes: edges 01, 12, 20
  const Vec2 mids[3] = {Vec2(0.5, 0), Vec2(0.5, 0.5), Vec2(0, 0.5)};
  for (int m = 0; m < 3; ++m) {
    ShapeN N;
    shape(FaceKind::Tri6, mids[m], N);
    for (int a = 0; a < 6; ++a) EXPECT_NEAR(N(a), a == 3 + m ? 1.0 : 0.0, 1e-14);
  }
}

// Compares against: central finite differences of N (first derivatives) and of dN (second derivatives).
TEST(Face, ShapeDerivativesMatchFiniteDifferences) {
  const double h = 1e-6;
  for (FaceKind k : kAll) {
    const Vec2 xi(0.27, 0.19);
    ShapeN N, Np, Nm;
    ShapeD dN, dNp, dNm;
    ShapeDD ddN;
    shape(k, xi, N, &dN, &ddN);
    for (int al = 0; al < 2; ++al) {
      Vec2 e = Vec2::Zero();
      e[al] = h;
      shape(k, xi + e, Np, &dNp);
      shape(k, xi - e, Nm, &dNm);
      EXPECT_LT((dN.col(al) - (Np - Nm) / (2 * h)).cwiseAbs().maxCoeff(), 1e-8) << name(k);
      const auto dd = (dNp - dNm) / (2 * h);  // column be: d2N/dxi_al dxi_be
      if (al == 0) {
        EXPECT_LT((ddN.col(0) - dd.col(0)).cwiseAbs().maxCoeff(), 1e-7);
        EXPECT_LT((ddN.col(2) - dd.col(1)).cwiseAbs().maxCoeff(), 1e-7);
      } else {
        EXPECT_LT((ddN.col(1) - dd.col(1)).cwiseAbs().maxCoeff(), 1e-7);
        EXPECT_LT((ddN.col(2) - dd.col(0)).cwiseAbs().maxCoeff(), 1e-7);
      }
    }
  }
}

// Compares against: the analytic normal (+z for counter-clockwise nodes seen from +z, flipped by normal_sign)
// and the exact area of flat faces (quadrature of j).
TEST(Face, NormalOrientationAndArea) {
  FaceX q(3, 4);
  q << 0, 2, 2, 0, 0, 0, 1, 1, 0, 0, 0, 0;
  const FacePoint p = evaluate(FaceKind::Quad4, q, Vec2(0.3, -0.2));
  EXPECT_NEAR((p.n - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((evaluate(FaceKind::Quad4, q, Vec2(0, 0), -1.0).n + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  for (int deg = 1; deg <= 7; ++deg) {
    double area = 0;
    const QuadratureRule r = face_rule(FaceKind::Quad4, deg);
    for (std::size_t i = 0; i < r.xi.size(); ++i) area += r.w[i] * evaluate(FaceKind::Quad4, q, r.xi[i]).j;
    EXPECT_NEAR(area, 2.0, 1e-14);
  }
  FaceX t(3, 6);
  t.leftCols<3>() << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  t.col(3) = 0.5 * (t.col(0) + t.col(1));
  t.col(4) = 0.5 * (t.col(1) + t.col(2));
  t.col(5) = 0.5 * (t.col(2) + t.col(0));
  for (int deg = 1; deg <= 4; ++deg) {
    double area = 0;
    const QuadratureRule r = face_rule(FaceKind::Tri6, deg);
    for (std::size_t i = 0; i < r.xi.size(); ++i) area += r.w[i] * evaluate(FaceKind::Tri6, t, r.xi[i]).j;
    EXPECT_NEAR(area, 0.5, 1e-14);
  }
  EXPECT_NEAR((evaluate(FaceKind::Tri6, t, Vec2(0.2, 0.2)).n - Vec3::UnitZ()).norm(), 0.0, 1e-15);
}

// Compares against: quadrature of polynomials of the stated degree (exact integrals on the reference domains).
TEST(Face, QuadratureExactness) {
  // quad: int x^4 y^2 over [-1,1]^2 = (2/5)(2/3)
  const QuadratureRule q = face_rule(FaceKind::Quad4, 5);
  double s = 0;
  for (std::size_t i = 0; i < q.xi.size(); ++i) s += q.w[i] * std::pow(q.xi[i][0], 4) * std::pow(q.xi[i][1], 2);
  EXPECT_NEAR(s, 4.0 / 15, 1e-14);
  // triangle: int x^2 y^2 = 2! 2! / 6! = 4/720
  const QuadratureRule t = face_rule(FaceKind::Tri6, 4);
  s = 0;
  for (std::size_t i = 0; i < t.xi.size(); ++i) s += t.w[i] * std::pow(t.xi[i][0], 2) * std::pow(t.xi[i][1], 2);
  EXPECT_NEAR(s, 4.0 / 720, 1e-12);
}

// Compares against: dense sampling of the curved face; every sampled surface point lies in face_box.
TEST(Face, BoxContainsCurvedFace) {
  FaceX X = cylinder_tri6(1.0);
  X.col(5) += Vec3(0.3, 0.2, -0.1);  // strongly curved tri6
  for (const auto& [k, F] : {std::pair{FaceKind::Tri6, X}, std::pair{FaceKind::Quad4, warped_quad()}}) {
    Aabb b = face_box(k, F);
    b.inflate(1e-12);
    for (int i = 0; i <= 50; ++i)
      for (int j = 0; j <= 50; ++j) {
        Vec2 xi = k == FaceKind::Quad4 ? Vec2(-1 + i / 25.0, -1 + j / 25.0) : Vec2(i / 50.0, j / 50.0);
        if (k == FaceKind::Tri6 && i + j > 50) continue;
        ShapeN N;
        shape(k, xi, N);
        EXPECT_TRUE(b.contains(F * N));
      }
  }
}
