// Closest-point projection and the linearization of the signed distance.
#include <gtest/gtest.h>

#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

namespace {
FaceX flat_quad() {  // [0,2] x [0,1] in z = 0, normal +z
  FaceX X(3, 4);
  X << 0, 2, 2, 0, 0, 0, 1, 1, 0, 0, 0, 0;
  return X;
}
}  // namespace

// Compares against: the exact orthogonal projection onto the plane z = 0.
TEST(Projection, FlatQuadInteriorBothSides) {
  const FaceX X = flat_quad();
  for (double z : {0.3, -0.2}) {
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(1.5, 0.25, z));
    ASSERT_TRUE(p.valid);
    EXPECT_EQ(p.location, Location::Interior);
    EXPECT_NEAR((p.s - Vec3(1.5, 0.25, 0)).norm(), 0, 1e-14);
    EXPECT_NEAR(p.d, z, 1e-14);
    EXPECT_NEAR(p.distance, std::abs(z), 1e-14);
    EXPECT_NEAR((p.n - Vec3::UnitZ()).norm(), 0, 1e-15);
    EXPECT_NEAR(p.xi[0], 0.5, 1e-14);
    EXPECT_NEAR(p.xi[1], -0.5, 1e-14);
  }
  // normal_sign = -1 flips n and d
  const Projection p = project(FaceKind::Quad4, X, -1.0, Vec3(1.5, 0.25, 0.3));
  EXPECT_NEAR(p.d, -0.3, 1e-14);
  EXPECT_NEAR((p.n + Vec3::UnitZ()).norm(), 0, 1e-15);
}

// Compares against: the exact closest points to a rectangle's edges and corners (point-to-edge normal).
TEST(Projection, FlatQuadEdgesAndCorners) {
  const FaceX X = flat_quad();
  {
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(2.5, 0.5, 0.3));
    EXPECT_EQ(p.location, Location::Edge);
    EXPECT_EQ(p.index, 1);
    EXPECT_NEAR((p.s - Vec3(2, 0.5, 0)).norm(), 0, 1e-13);
    EXPECT_NEAR(p.d, std::hypot(0.5, 0.3), 1e-13);
    EXPECT_NEAR((p.n - Vec3(0.5, 0, 0.3).normalized()).norm(), 0, 1e-13);
  }
  {  // from below: d < 0, n still on the +z side
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(2.5, 0.5, -0.3));
    EXPECT_EQ(p.location, Location::Edge);
    EXPECT_NEAR(p.d, -std::hypot(0.5, 0.3), 1e-13);
    EXPECT_NEAR((p.n - Vec3(-0.5, 0, 0.3).normalized()).norm(), 0, 1e-13);
    EXPECT_GT(p.n.dot(Vec3::UnitZ()), 0);
  }
  {
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(2.5, 1.5, 0.3));
    EXPECT_EQ(p.location, Location::Corner);
    EXPECT_EQ(p.index, 2);
    EXPECT_NEAR((p.s - Vec3(2, 1, 0)).norm(), 0, 1e-14);
  }
  {
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(-0.5, -0.1, -0.3));
    EXPECT_EQ(p.location, Location::Corner);
    EXPECT_EQ(p.index, 0);
  }
  {  // bottom edge (edge 0)
    const Projection p = project(FaceKind::Quad4, X, 1.0, Vec3(0.7, -0.4, 0.1));
    EXPECT_EQ(p.location, Location::Edge);
    EXPECT_EQ(p.index, 0);
    EXPECT_NEAR((p.s - Vec3(0.7, 0, 0)).norm(), 0, 1e-13);
  }
}

// Compares against: brute-force minimization (dense sampling + pattern search) of |x - x_s(xi)| on a warped
// quad4 and a tri6 on a cylinder, for points on both sides, inside, near edges and near corners.
TEST(Projection, CurvedFacesMatchBruteForce) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> U(-1, 1);
  struct Case {
    FaceKind k;
    FaceX X;
  };
  const Case cases[] = {{FaceKind::Quad4, warped_quad()}, {FaceKind::Tri6, cylinder_tri6(1.0)}};
  int counts[3] = {0, 0, 0};
  for (const Case& c : cases) {
    for (int trial = 0; trial < 60; ++trial) {
      // parameter point possibly outside the domain (near edges/corners), then offset along the normal
      Vec2 xi =
          c.k == FaceKind::Quad4 ? Vec2(1.3 * U(rng), 1.3 * U(rng)) : Vec2(0.4 + 0.8 * U(rng), 0.3 + 0.8 * U(rng));
      const FacePoint fp = evaluate(c.k, c.X, xi);
      const Vec3 x = fp.x + 0.25 * U(rng) * fp.n;
      const Projection p = project(c.k, c.X, 1.0, x);
      ASSERT_TRUE(p.valid);
      const double ref = brute_distance(c.k, c.X, x);
      EXPECT_NEAR(p.distance, ref, 1e-9) << name(c.k) << " trial " << trial << " loc " << name(p.location);
      ++counts[static_cast<int>(p.location)];
      // stationarity: (x - s) orthogonal to the tangents (interior) / edge tangent (edge)
      const FacePoint sp = evaluate(c.k, c.X, p.xi);
      const Vec3 r = x - p.s;
      if (p.location == Location::Interior) {
        EXPECT_NEAR(r.dot(sp.a1), 0, 1e-11);
        EXPECT_NEAR(r.dot(sp.a2), 0, 1e-11);
        EXPECT_NEAR(std::abs(p.d), p.distance, 1e-12);
      }
      EXPECT_NEAR(std::abs(p.d), p.distance, 1e-12);
      EXPECT_GE(p.n.dot(p.n_face), -1e-12);  // the contact normal is on the side of the face normal
    }
  }
  EXPECT_GT(counts[0], 10);  // the sample covers interior, edge and corner cases
  EXPECT_GT(counts[1], 5);
  EXPECT_GT(counts[2], 3);
}

// Compares against: the exact cylinder (tri6 with nodes on a cylinder of radius 1 approximates it to ~1e-3):
// points at radius 1.1 (outside) and 0.9 (inside) have d = +-0.1 and a radial normal.
TEST(Projection, Tri6OnCylinderBothSides) {
  const FaceX X = cylinder_tri6(1.0);
  for (double rad : {1.1, 0.9}) {
    const Vec3 x = cyl(rad, 0.35, 0.1);
    const Projection p = project(FaceKind::Tri6, X, 1.0, x);
    EXPECT_EQ(p.location, Location::Interior);
    EXPECT_NEAR(p.d, rad - 1.0, 2e-3);
    EXPECT_NEAR(p.n.dot(Vec3(std::cos(0.35), std::sin(0.35), 0)), 1.0, 1e-3);
  }
}

namespace {
// Check dd, dn, dxi and hd of `linearize` against central differences of re-projections.
void check_linearization(FaceKind k, const FaceX& X, double sign, const Vec3& x, Location expect) {
  const Projection p = project(k, X, sign, x);
  ASSERT_EQ(p.location, expect) << name(k);
  GapLinearization L;
  linearize(k, X, sign, x, p, true, L);
  const int nn = num_nodes(k);
  Eigen::VectorXd u(3 + 3 * nn);
  u.head<3>() = x;
  u.tail(3 * nn) = flatten(X);
  auto split = [&](const Eigen::VectorXd& v, Vec3& xx, FaceX& XX) {
    xx = v.head<3>();
    XX = unflatten(v.tail(3 * nn));
  };
  auto fd = [&](const Eigen::VectorXd& v) {
    Vec3 xx;
    FaceX XX;
    split(v, xx, XX);
    const Projection q = project(k, XX, sign, xx);
    EXPECT_EQ(q.location, p.location);
    Eigen::VectorXd out(6);
    out << q.d, q.n, q.xi;
    return out;
  };
  const Eigen::MatrixXd J = fd_jacobian(fd, u, 1e-6);
  EXPECT_LT(rel_diff(L.dd, J.row(0)), 1e-7) << name(k) << " dd";
  EXPECT_LT(rel_diff(L.dn, J.middleRows(1, 3)), 1e-6) << name(k) << " dn";
  EXPECT_LT(rel_diff(L.dxi, J.bottomRows(2)), 1e-6) << name(k) << " dxi";
  auto grad = [&](const Eigen::VectorXd& v) {
    Vec3 xx;
    FaceX XX;
    split(v, xx, XX);
    const Projection q = project(k, XX, sign, xx);
    GapLinearization M;
    linearize(k, XX, sign, xx, q, false, M);
    return Eigen::VectorXd(M.dd.transpose());
  };
  const Eigen::MatrixXd H = fd_jacobian(grad, u, 1e-6);
  EXPECT_LT(rel_diff(L.hd, H), 1e-6) << name(k) << " hd";
  EXPECT_LT(rel_diff(L.hd, L.hd.transpose()), 1e-12) << name(k) << " hd symmetric";
}
}  // namespace

// Compares against: central finite differences (h = 1e-6 mm) of d, n, xi and of the analytic gradient.
TEST(Projection, LinearizationMatchesFiniteDifferences) {
  const FaceX W = warped_quad();
  const FaceX T = cylinder_tri6(1.0);
  // interior, both sides, both sign conventions
  for (double off : {0.2, -0.15}) {
    const FacePoint fp = evaluate(FaceKind::Quad4, W, Vec2(0.2, -0.3));
    check_linearization(FaceKind::Quad4, W, 1.0, fp.x + off * fp.n, Location::Interior);
    check_linearization(FaceKind::Quad4, W, -1.0, fp.x + off * fp.n, Location::Interior);
    const FacePoint tp = evaluate(FaceKind::Tri6, T, Vec2(0.3, 0.2));
    check_linearization(FaceKind::Tri6, T, 1.0, tp.x + off * tp.n, Location::Interior);
  }
  // edge and corner
  {
    const FacePoint fp = evaluate(FaceKind::Quad4, W, Vec2(1.3, 0.1));
    check_linearization(FaceKind::Quad4, W, 1.0, fp.x + 0.1 * fp.n, Location::Edge);
    check_linearization(FaceKind::Quad4, W, 1.0, fp.x - 0.1 * fp.n, Location::Edge);
    const FacePoint cp = evaluate(FaceKind::Quad4, W, Vec2(1.3, 1.4));
    check_linearization(FaceKind::Quad4, W, 1.0, cp.x + 0.1 * cp.n, Location::Corner);
    const FacePoint tp = evaluate(FaceKind::Tri6, T, Vec2(0.6, 0.6));  // beyond the straight edge 12
    check_linearization(FaceKind::Tri6, T, 1.0, tp.x + 0.05 * tp.n, Location::Edge);
    const FacePoint hp = evaluate(FaceKind::Tri6, T, Vec2(-0.15, 0.5));  // beyond the curved (helical) edge 20
    check_linearization(FaceKind::Tri6, T, 1.0, hp.x + 0.05 * hp.n, Location::Edge);
    check_linearization(FaceKind::Tri6, T, 1.0, hp.x - 0.05 * hp.n, Location::Edge);
  }
}

// Compares against: brute-force minimization (dense sampling + pattern search) on randomly distorted quad4/tri3/tri6
// faces (strongly warped and curved, non-uniform node spacing) for random points up to half a face size away, on both
// sides.
#ifndef NFACE
#define NFACE 12
#endif
TEST(Projection, RandomDistortedFacesMatchBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  int n = 0;
  for (FaceKind k : {FaceKind::Quad4, FaceKind::Tri3, FaceKind::Tri6}) {
    for (int face = 0; face < NFACE; ++face) {
      FaceX X(3, num_nodes(k));
      for (int c = 0; c < num_corners(k); ++c) {
        const Vec2 xi = corner_xi(k, c);
        X.col(c) = Vec3(xi[0], xi[1], 0) + Vec3(0.2 * U(rng), 0.2 * U(rng), 0.25 * U(rng));
      }
      if (k == FaceKind::Tri6) {
        const int e[3][2] = {{0, 1}, {1, 2}, {2, 0}};
        for (int m = 0; m < 3; ++m)
          X.col(3 + m) = 0.5 * (X.col(e[m][0]) + X.col(e[m][1])) + Vec3(0.05 * U(rng), 0.05 * U(rng), 0.15 * U(rng));
      }
      for (int trial = 0; trial < 8; ++trial) {
        const Vec2 xi =
            k == FaceKind::Quad4 ? Vec2(1.2 * U(rng), 1.2 * U(rng)) : Vec2(0.4 + 0.6 * U(rng), 0.3 + 0.6 * U(rng));
        const FacePoint fp = evaluate(k, X, xi);
        const Vec3 x = fp.x + 0.5 * U(rng) * fp.n;
        const Projection p = project(k, X, 1.0, x);
        // |x - x_s(p.xi)| is an upper bound of the true minimum; it must not exceed the brute-force minimum
        // (which may itself stop slightly above the true minimum)
        EXPECT_TRUE(inside(k, p.xi, 1e-10));
        EXPECT_LE(p.distance, brute_distance(k, X, x) + 1e-9) << name(k) << " face " << face << " " << name(p.location);
        ++n;
      }
    }
  }
  EXPECT_EQ(n, 3 * NFACE * 8);
}
