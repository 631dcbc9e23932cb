// Bow of the device axis (axis_bow.hpp), the straightening measure of the curved free expansion.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/beam/axis_bow.hpp"
#include "angio/beam/ring_axis.hpp"
#include "angio/beam/stent_generator.hpp"
#include "angio/geometry/centerline.hpp"

using namespace angio::beam;

namespace {
// A planar circular arc of radius R, 24 mm long, in the x–z plane (401 points).
std::vector<Vec3> arc_points(double R) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= 400; ++i) {
    const double a = 24.0 / R * i / 400;
    pts.emplace_back(R * (1 - std::cos(a)), 0.0, R * std::sin(a));
  }
  return pts;
}
}  // namespace

// Analytic: three points on a circle of radius R at angles −θ, 0, θ have chord 2R sin θ, sagitta
// R(1 − cos θ) and circumradius R; collinear points are straight (infinite radius, zero sagitta).
TEST(AxisBow, PointsOnACircle) {
  const double R = 15.0, th = 0.55;
  const Vec3 c(1.0, -2.0, 0.5);
  const auto on = [&](double a) { return Vec3(c.x() + R * std::sin(a), c.y() + R * std::cos(a), c.z()); };
  const AxisBow b = axis_bow(on(-th), on(0.0), on(th));
  EXPECT_NEAR(b.chord, 2 * R * std::sin(th), 1e-12);
  EXPECT_NEAR(b.sagitta, R * (1 - std::cos(th)), 1e-12);
  EXPECT_NEAR(b.radius, R, 1e-11);
  const AxisBow s = axis_bow(Vec3(0, 0, 0), Vec3(0, 0, 3.0), Vec3(0, 0, 6.0));
  EXPECT_EQ(s.sagitta, 0.0);
  EXPECT_TRUE(std::isinf(s.radius));
}

// A generated 11-ring stent (16.5 mm) warped onto a planar arc of radius 15 mm: the bow through
// the crown centroids recovers the arc. The end centroids lie on the axis; the middle crowns sit
// at the ring's two edges 1.5 mm apart, so their centroid lies 1.5²/(8·15) = 0.019 mm inside the
// arc, which raises the radius by ≈ 0.9 % (tolerance 2 %). The straight stent has no bow.
TEST(AxisBow, GeneratedStentOnAnArc) {
  const double R = 15.0;
  const std::vector<Vec3> pts = arc_points(R);
  StentParameters p;
  p.rings = 11;
  const angio::geometry::Centerline axis(pts);
  for (bool curved : {true, false}) {
    const StentMesh m = curved ? generate_corrugated_rings(p, pts) : generate_corrugated_rings(p);
    std::vector<Vec3> distal, central;
    std::vector<double> s;
    for (int n : m.distal_nodes) {
      distal.push_back(m.nodes[n]);
      s.push_back(curved ? axis.closest(m.nodes[n]).s : m.nodes[n].z());
    }
    for (int n : m.central_nodes) central.push_back(m.nodes[n]);
    const AxisBow b = stent_axis_bow(distal, s, central);
    if (curved) {
      EXPECT_NEAR(b.radius, R, 0.02 * R);
      EXPECT_GT(b.sagitta, 2.0);  // ≈ 2.2 mm for a 16.5 mm arc of radius 15 mm
    } else {
      EXPECT_LT(b.sagitta, 1e-12);
    }
  }
}

// The halves' bows (stent_half_bows). Analytic: on the arc of radius 15 mm every ring centroid lies
// on the arc (inside it by ≈ 0.02 mm, as above), so both halves have radius 15 mm (2 %); a straight
// stent has straight halves; a straight stent kinked at its middle ring (rings beyond it rotated
// by 0.3 rad about the middle ring's centroid) has straight halves while the whole-device bow
// through ends and middle reads a finite radius, the case the halves are there to tell apart.
TEST(AxisBow, HalvesOfAStent) {
  const double R = 15.0;
  const std::vector<Vec3> pts = arc_points(R);
  StentParameters p;
  p.rings = 11;
  // the ring centroids as the beam solver takes them (ring_centroid_axis)
  auto centroids = [](const StentMesh& m, const std::vector<Vec3>& x) {
    return ring_centroid_axis(m.ring_crowns, x).value().points;
  };
  const StentMesh arc = generate_corrugated_rings(p, pts);
  ASSERT_EQ(arc.ring_crowns.size(), 11u);
  for (const AxisBow& h : stent_half_bows(centroids(arc, arc.nodes))) EXPECT_NEAR(h.radius, R, 0.02 * R);

  const StentMesh straight = generate_corrugated_rings(p);
  for (const AxisBow& h : stent_half_bows(centroids(straight, straight.nodes))) EXPECT_TRUE(std::isinf(h.radius));

  std::vector<Vec3> x = straight.nodes;
  const Vec3 pivot = centroids(straight, x)[5];
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix();
  for (int k = 6; k < 11; ++k)
    for (int n : straight.ring_crowns[k]) x[n] = pivot + rot * (straight.nodes[n] - pivot);
  const std::vector<Vec3> c = centroids(straight, x);
  const auto halves = stent_half_bows(c);
  EXPECT_GT(halves[0].radius, 1e6);
  EXPECT_GT(halves[1].radius, 1e6);
  EXPECT_LT(axis_bow(c[0], pivot, c[10]).radius, 100.0);  // 16.5 mm kinked by 0.3 rad: ≈ 28 mm

  const std::vector<Vec3> four(c.begin(), c.begin() + 4);
  EXPECT_TRUE(std::isnan(stent_half_bows(four)[0].radius));
}
