// The virtual-insertion capsule (capsule_tool.hpp): distance to a polyline and the node penalty.
// Consistency checks: r = dΠ/dx and K = dr/dx by central differences, inside a segment (P = I − t tᵀ)
// and at a rounded end and an outer corner (P = I); no force outside the capsule.
#include <gtest/gtest.h>

#include "angio/contact/capsule_tool.hpp"

using namespace angio::contact;

namespace {

void check_fd(const std::vector<Vec3>& axis, const Vec3& x, double R, double eps_area) {
  const auto at = [&](const Vec3& y) { return capsule_node(polyline_distance(axis, y), R, eps_area); };
  const ToolNodeContact c = at(x);
  ASSERT_TRUE(c.active) << "x = " << x.transpose();
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Vec3 xp = x, xm = x;
    xp(k) += h;
    xm(k) -= h;
    const ToolNodeContact p = at(xp), m = at(xm);
    EXPECT_NEAR(c.r(k), (p.energy - m.energy) / (2 * h), 1e-6 * eps_area) << "component " << k;
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(c.K(i, k), (p.r(i) - m.r(i)) / (2 * h), 1e-5 * eps_area) << "K(" << i << "," << k << ")";
  }
}

}  // namespace

TEST(CapsuleTool, DistanceToAPolyline) {
  const std::vector<Vec3> axis = {Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(1, 0, 3)};
  const AxisDistance in = polyline_distance(axis, Vec3(0.3, 0.4, 1.0));  // beside the first segment
  EXPECT_NEAR(in.r, 0.5, 1e-14);
  EXPECT_NEAR((in.foot - Vec3(0, 0, 1)).norm(), 0.0, 1e-14);
  EXPECT_NEAR(in.P(2, 2), 0.0, 1e-14);                                   // no change of r along the axis
  const AxisDistance end = polyline_distance(axis, Vec3(0, 0.6, -0.8));  // beyond the first end: a sphere
  EXPECT_NEAR(end.r, 1.0, 1e-14);
  EXPECT_TRUE(end.P.isIdentity(1e-14));
}

TEST(CapsuleTool, PenaltyDerivativesByFiniteDifferences) {
  const std::vector<Vec3> axis = {Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(1, 0, 3)};
  const double R = 0.7, eps_area = 3.0;
  check_fd(axis, Vec3(0.3, 0.2, 1.0), R, eps_area);   // inside the first segment's cylinder
  check_fd(axis, Vec3(0.4, 0.35, 2.5), R, eps_area);  // beside the second, oblique segment
  check_fd(axis, Vec3(0.1, 0.2, -0.3), R, eps_area);  // the rounded end
  check_fd(axis, Vec3(-0.3, 0.1, 2.1), R, eps_area);  // the outer corner at the bend (vertex)
}

TEST(CapsuleTool, NoForceOutsideAndOutwardInside) {
  const std::vector<Vec3> axis = {Vec3(0, 0, 0), Vec3(0, 0, 4)};
  EXPECT_FALSE(capsule_node(polyline_distance(axis, Vec3(0.8, 0, 2)), 0.7, 1.0).active);
  const ToolNodeContact c = capsule_node(polyline_distance(axis, Vec3(0.5, 0, 2)), 0.7, 2.0);
  ASSERT_TRUE(c.active);
  EXPECT_NEAR(c.penetration, 0.2, 1e-14);
  EXPECT_NEAR(-c.r(0), 2.0 * 0.2, 1e-14);  // force ε A (R − r), outward (+x)
  EXPECT_NEAR(c.r(1), 0.0, 1e-14);
  EXPECT_NEAR(c.r(2), 0.0, 1e-14);
}
