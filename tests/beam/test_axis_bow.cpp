// Bow of the device axis (axis_bow.hpp), the straightening measure of the curved free expansion.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/beam/axis_bow.hpp"
#include "angio/beam/stent_generator.hpp"
#include "angio/geometry/centerline.hpp"

using namespace angio::beam;

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
  std::vector<Vec3> pts;
  for (int i = 0; i <= 400; ++i) {
    const double a = 24.0 / R * i / 400;
    pts.emplace_back(R * (1 - std::cos(a)), 0.0, R * std::sin(a));
  }
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
