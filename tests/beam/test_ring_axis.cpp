// Stent diameter about, and length along, the axis of the deformed stent (ring_axis.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "angio/beam/ring_axis.hpp"
#include "angio/beam/stent_generator.hpp"

using namespace angio::beam;

namespace {
std::vector<Vec3> arc(double R, double length) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= 400; ++i) {
    const double a = length / R * i / 400;
    pts.emplace_back(R * (1 - std::cos(a)), 0.0, R * std::sin(a));
  }
  return pts;
}
}  // namespace

// Analytic: every node of a generated straight stent lies on the cylinder of the crimped radius,
// so its diameter is the crimped diameter. After a rigid motion (rotation + a lateral shift of
// 0.3 mm, half the radius) the ring axis still gives it to round-off, while the reference axis
// overestimates it (mean distance of a shifted circle, r(1 + δ²/(4r²)) to leading order).
TEST(RingAxis, RigidMotionKeepsTheDiameter) {
  StentParameters p;
  p.rings = 4;
  const StentMesh m = generate_corrugated_rings(p);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.4, Vec3(1, 2, 0.5).normalized()).toRotationMatrix();
  const Vec3 shift(0.3, -0.1, 2.0);
  std::vector<Vec3> x;
  for (const auto& X : m.nodes) x.push_back(Q * X + shift);
  const auto axis = ring_centroid_axis(m.ring_crowns, x);
  ASSERT_TRUE(axis.has_value());
  EXPECT_NEAR(mean_diameter(*axis, x), p.crimped_diameter, 1e-12);
  EXPECT_NEAR(mean_diameter(*axis, x, m.central_nodes), p.crimped_diameter, 1e-12);
  EXPECT_NEAR(mean_diameter(*axis, x, m.distal_nodes), p.crimped_diameter, 1e-12);
  Axis reference;
  reference.points = m.axis;
  const double r = 0.5 * p.crimped_diameter, d = Vec3(shift.x(), shift.y(), 0).norm();
  EXPECT_NEAR(mean_diameter(reference, m.nodes), p.crimped_diameter, 1e-12);
  std::vector<Vec3> shifted;
  for (const auto& X : m.nodes) shifted.push_back(X + Vec3(shift.x(), shift.y(), 0));
  EXPECT_GT(mean_diameter(reference, shifted), p.crimped_diameter * (1 + 0.5 * d * d / (4 * r * r)));
}

// Consistency: an 11-ring stent warped onto an arc of radius R = 15 mm. The nodes lie at the
// crimped radius from the arc; the polyline through the ring centroids departs from the arc by at
// most the chord sagitta pitch²/(8R) between centroids, plus the centroid's own offset from the
// arc (the crowns sit at the ring's two edges, h²/(8R)), and beyond the end centroids by the
// tangent offset (h/2)²/(2R) over half a strut height. Each node's distance changes by at most the
// sum, so the diameter by at most twice it (0.11 mm; the measure is off by 0.002 mm); the arc bows
// by 2.2 mm over the stent.
TEST(RingAxis, CurvedStentKeepsTheCrimpedDiameter) {
  const double R = 15.0;
  StentParameters p;
  p.rings = 11;
  const StentMesh m = generate_corrugated_rings(p, arc(R, 24.0));
  const auto axis = ring_centroid_axis(m.ring_crowns, m.nodes);
  ASSERT_TRUE(axis.has_value());
  EXPECT_EQ(axis->points.size(), 11u);
  const double h = p.strut_height;
  const double bound = 2 * (p.ring_pitch * p.ring_pitch / (8 * R) + h * h / (8 * R) + 0.25 * h * h / (2 * R));
  EXPECT_NEAR(mean_diameter(*axis, m.nodes), p.crimped_diameter, bound);
  EXPECT_NEAR(mean_diameter(*axis, m.nodes, m.central_nodes), p.crimped_diameter, bound);
  EXPECT_NEAR(mean_diameter(*axis, m.nodes, m.distal_nodes), p.crimped_diameter, bound);
}

// Length along the deformed axis. Analytic: the straight 4-ring stent spans rings × pitch = 6 mm
// (its end crowns lie on the end planes, the ring axis extends along the same line), after any
// rigid motion too, where its extent along the reference axis shrinks with the rotation (to at
// most L cos a + D sin a < L).
// Consistency: warped onto an arc of R = 15 mm without stretching, the 11-ring stent spans 16.5 mm
// of arc. Along the ring polyline the interior is shorter by the chord-vs-arc difference; the
// extent is set by the end crowns, which project onto the straight extensions beyond the end
// centroids: a crown on the outer side of the bend, at r + δ from the polyline (δ = h²/(8R), the
// centroid's own offset), lies (h/2)(1 + (r + δ)/R) beyond along the arc tangent, plus r·sin(φ/2)
// because the extension follows the end chord, turned by half the chord angle φ = pitch/R. So
// 16.5 ≤ L ≤ 16.5 + 2[(h/2)(r + δ)/R + r φ/2] (+0.117 mm; measured +0.083). The same stent moved
// 0.5 mm sideways is as long along its own axis.
TEST(RingAxis, LengthAlongTheDeformedAxis) {
  StentParameters p;
  p.rings = 4;
  const StentMesh m = generate_corrugated_rings(p);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.4, Vec3(1, 0, 0)).toRotationMatrix();
  std::vector<Vec3> x;
  for (const auto& X : m.nodes) x.push_back(Q * X + Vec3(0.3, -0.1, 2.0));
  const double L = p.rings * p.ring_pitch;
  EXPECT_NEAR(length_along(*ring_centroid_axis(m.ring_crowns, m.nodes), m.nodes), L, 1e-9);
  EXPECT_NEAR(length_along(*ring_centroid_axis(m.ring_crowns, x), x), L, 1e-9);
  Axis reference;
  reference.points = m.axis;
  // nodes on the cylinder of diameter D rotated by a about x: extent along z <= L cos a + D sin a
  const double shrunk = L * std::cos(0.4) + p.crimped_diameter * std::sin(0.4);
  ASSERT_LT(shrunk, L - 0.01);
  EXPECT_LT(length_along(reference, x), shrunk + 1e-9);

  const double R = 15.0;
  StentParameters q;
  q.rings = 11;
  const StentMesh c = generate_corrugated_rings(q, arc(R, 24.0));
  const double Lc = q.rings * q.ring_pitch;
  const double r = 0.5 * q.crimped_diameter, h = q.strut_height, delta = h * h / (8 * R);
  const double excess = 2 * (0.5 * h * (r + delta) / R + r * 0.5 * q.ring_pitch / R);
  const double Lcurved = length_along(*ring_centroid_axis(c.ring_crowns, c.nodes), c.nodes);
  EXPECT_GE(Lcurved, Lc - Lc * std::pow(q.ring_pitch / R, 2) / 24);
  EXPECT_LE(Lcurved, Lc + excess);
  std::vector<Vec3> moved;
  for (const auto& X : c.nodes) moved.push_back(X + Vec3(0.5, 0, 0));
  EXPECT_NEAR(length_along(*ring_centroid_axis(c.ring_crowns, moved), moved), Lcurved, 1e-9);
}

// One ring has no axis of its own: the caller keeps the reference axis.
TEST(RingAxis, OneRingHasNoAxis) {
  StentParameters p;
  p.rings = 1;
  const StentMesh m = generate_corrugated_rings(p);
  EXPECT_FALSE(ring_centroid_axis(m.ring_crowns, m.nodes).has_value());
}
