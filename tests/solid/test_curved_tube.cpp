// Curved tube generator (solid_solver make_tube with a centerline; paper §2.4: the balloon is a
// hollow cylinder along the centerline, warped like the stent; §3.2: 18 mm curved balloon).
// Each test states what it compares against.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "angio/solid/mesh.hpp"

using namespace angio::solid;
using angio::geometry::Centerline;

namespace {

// Planar circular arc of radius rho in the x–z plane, from the origin along +z, uniform spacing:
// the vertex tangents (central chords) and their slerp are then the exact arc tangents.
Centerline arc(double rho, double length, int n) {
  std::vector<Vec3d> p;
  for (int i = 0; i <= n; ++i) {
    const double a = length / rho * i / n;
    p.emplace_back(rho * (1 - std::cos(a)), 0.0, rho * std::sin(a));
  }
  return Centerline(p);
}

TubeSpec balloon_spec() {
  TubeSpec t;
  t.part = "balloon";
  t.surface_prefix = "balloon_";
  t.length = 18.0;
  t.inner_radius = 0.45;
  t.layers = {{"balloon", 0.04, 1}};
  t.n_circ = 22;
  t.n_axial = 126;
  return t;
}

double hex_jacobian_min(const Mesh& m, int e) {
  Eigen::MatrixXd X(8, 3);
  for (int a = 0; a < 8; ++a) X.row(a) = m.X[m.elements[e].n[a]].transpose();
  double jmin = 1e300;
  for (const auto& q : volume_rule(ElemType::Hex8)) {
    Eigen::VectorXd N;
    Eigen::MatrixXd dN;
    shape(ElemType::Hex8, q.xi, N, dN);
    jmin = std::min(jmin, (X.transpose() * dN).determinant());
  }
  return jmin;
}

}  // namespace

// Every node of the warped tube sits at exactly its shell radius (0.45 inner, 0.49 outer) from
// the curved axis, at arc length start + z (compared with the radii and stations of the straight
// tube it was warped from, to round-off), and every hex8 keeps a positive Jacobian.
TEST(CurvedTube, NodesAtTheirRadiusFromTheCenterline) {
  TubeSpec t = balloon_spec();
  t.centerline = arc(15.0, 24.0, 96);
  t.start = 3.0;
  const Mesh m = make_tube(t);
  ASSERT_EQ(m.elements.size(), 22u * 126u);
  ASSERT_EQ(m.X.size(), 22u * 2u * 127u);
  for (size_t n = 0; n < m.X.size(); ++n) {
    const int k = int(n / 44), j = int(n / 22) % 2;
    const auto p = t.centerline->closest(m.X[n]);
    EXPECT_NEAR(p.distance, j == 0 ? 0.45 : 0.49, 1e-12) << "node " << n;
    EXPECT_NEAR(p.s, 3.0 + 18.0 * k / 126, 1e-10) << "node " << n;
  }
  for (size_t e = 0; e < m.elements.size(); ++e) EXPECT_GT(hex_jacobian_min(m, int(e)), 0.0);
}

// Fiber frames of the warped balloon: orthonormal and right-handed, the axial direction is the
// tangent of the arc at the element (compared with the analytic tangent (sin s/ρ, 0, cos s/ρ)
// at the element's mid station; 1e-3 covers the centroid's offset from the mid station) and
// with the element's own axial edge direction; radial points away from the axis.
TEST(CurvedTube, FiberFramesFollowTheCurvedAxis) {
  TubeSpec t = balloon_spec();
  t.centerline = arc(15.0, 24.0, 96);
  t.start = 3.0;
  const Mesh m = make_tube(t);
  ASSERT_EQ(m.frames.size(), m.elements.size());
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const Frame& f = m.frames[e];
    EXPECT_NEAR(f.axial.norm(), 1.0, 1e-12);
    EXPECT_NEAR(f.radial.norm(), 1.0, 1e-12);
    EXPECT_NEAR(f.circumferential.norm(), 1.0, 1e-12);
    EXPECT_NEAR(f.axial.dot(f.radial), 0.0, 1e-12);
    EXPECT_NEAR(f.axial.dot(f.circumferential), 0.0, 1e-12);
    EXPECT_NEAR(f.radial.dot(f.circumferential), 0.0, 1e-12);
    EXPECT_NEAR(f.axial.cross(f.radial).dot(f.circumferential), 1.0, 1e-12);
    const int k = int(e) / 22;
    const double s = 3.0 + 18.0 * (k + 0.5) / 126;
    const Vec3d T(std::sin(s / 15.0), 0.0, std::cos(s / 15.0));
    EXPECT_NEAR(f.axial.dot(T), 1.0, 1e-6) << "element " << e;
    const auto& n = m.elements[e].n;
    Vec3d edge = Vec3d::Zero();
    for (int a = 4; a < 8; ++a) edge += m.X[n[a]] - m.X[n[a - 4]];
    EXPECT_NEAR(f.axial.dot(edge.normalized()), 1.0, 1e-4) << "element " << e;
    const Vec3d c = element_centroid(m, int(e));
    EXPECT_GT(f.radial.dot(c - t.centerline->closest(c).foot), 0.0);
    EXPECT_NEAR(f.axial.dot(t.centerline->frame(t.centerline->closest(c).s).tangent), 1.0, 1e-14);
  }
}

// Surfaces of the curved tube: inner faces face the axis, outer faces face away, end0/end1 lie
// in the normal planes at arc length start and start + length (compared with those stations).
TEST(CurvedTube, SurfacesAndEnds) {
  TubeSpec t = balloon_spec();
  t.centerline = arc(15.0, 24.0, 96);
  t.start = 2.0;
  const Mesh m = make_tube(t);
  for (const char* name : {"balloon_inner", "balloon_outer", "balloon_end0", "balloon_end1"})
    ASSERT_NE(m.surface(name), nullptr) << name;
  auto face_check = [&](const char* name, auto&& check) {
    for (const auto& f : m.surface(name)->faces) {
      Eigen::MatrixXd X(4, 3);
      Vec3d fc = Vec3d::Zero();
      for (int a = 0; a < 4; ++a) {
        X.row(a) = m.X[f.n[a]].transpose();
        fc += m.X[f.n[a]] / 4;
      }
      check(face_area_vector(f.type, X), fc);
    }
  };
  face_check("balloon_inner",
             [&](const Vec3d& A, const Vec3d& fc) { EXPECT_LT(A.dot(fc - t.centerline->closest(fc).foot), 0.0); });
  face_check("balloon_outer",
             [&](const Vec3d& A, const Vec3d& fc) { EXPECT_GT(A.dot(fc - t.centerline->closest(fc).foot), 0.0); });
  face_check("balloon_end0", [&](const Vec3d& A, const Vec3d& fc) {
    EXPECT_NEAR(t.centerline->closest(fc).s, 2.0, 1e-10);
    EXPECT_LT(A.dot(t.centerline->frame(2.0).tangent), 0.0);  // out of the tube: backwards
  });
  face_check("balloon_end1", [&](const Vec3d& A, const Vec3d& fc) {
    EXPECT_NEAR(t.centerline->closest(fc).s, 20.0, 1e-10);
    EXPECT_GT(A.dot(t.centerline->frame(20.0).tangent), 0.0);
  });
}

// A straight centerline reproduces the straight tube node for node (compared with make_tube
// without a centerline, centred at the same point): nodes to round-off, identical connectivity
// and surfaces, equal fiber frames.
TEST(CurvedTube, StraightCenterlineReproducesStraightTube) {
  TubeSpec a = balloon_spec();
  a.n_axial = 58;
  a.length = 9.4;
  a.center = Vec3d(0.2, -0.1, 3.0);
  TubeSpec b = a;
  b.centerline =
      Centerline({Vec3d(0.2, -0.1, 3.0 - 4.7 - 1.0), Vec3d(0.2, -0.1, 3.0), Vec3d(0.2, -0.1, 3.0 + 4.7 + 2.0)});
  b.start = 1.0;
  const Mesh ma = make_tube(a), mb = make_tube(b);
  ASSERT_EQ(ma.X.size(), mb.X.size());
  for (size_t n = 0; n < ma.X.size(); ++n) EXPECT_LT((ma.X[n] - mb.X[n]).norm(), 1e-13) << "node " << n;
  ASSERT_EQ(ma.elements.size(), mb.elements.size());
  for (size_t e = 0; e < ma.elements.size(); ++e) {
    EXPECT_EQ(ma.elements[e].n, mb.elements[e].n);
    EXPECT_LT((ma.frames[e].axial - mb.frames[e].axial).norm(), 1e-12);
    EXPECT_LT((ma.frames[e].radial - mb.frames[e].radial).norm(), 1e-12);
    EXPECT_LT((ma.frames[e].circumferential - mb.frames[e].circumferential).norm(), 1e-12);
  }
  ASSERT_EQ(ma.surfaces.size(), mb.surfaces.size());
  for (size_t s = 0; s < ma.surfaces.size(); ++s) {
    EXPECT_EQ(ma.surfaces[s].name, mb.surfaces[s].name);
    ASSERT_EQ(ma.surfaces[s].faces.size(), mb.surfaces[s].faces.size());
    for (size_t f = 0; f < ma.surfaces[s].faces.size(); ++f)
      EXPECT_EQ(ma.surfaces[s].faces[f].n, mb.surfaces[s].faces[f].n);
  }
  EXPECT_EQ(ma.node_sets, mb.node_sets);
}

// A tube that does not fit on its centerline is rejected (the scene turns this into an error
// naming balloon.mesh.length / .start).
TEST(CurvedTube, LongerThanCenterlineThrows) {
  TubeSpec t = balloon_spec();
  t.centerline = arc(15.0, 16.0, 64);
  t.start = 0.0;
  EXPECT_THROW(make_tube(t), std::runtime_error);
}
