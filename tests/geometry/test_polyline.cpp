// Closest point of a polyline (core/geometry/polyline.hpp), against hand-computed feet on an
// L-shaped polyline: beside a segment, at the inner corner, beyond either end with the ends
// clamped (a capsule's caps) and extended (an axis longer than its points).
#include <gtest/gtest.h>

#include "angio/geometry/polyline.hpp"

using angio::geometry::closest_on_polyline;
using angio::geometry::PolylineEnds;
using angio::geometry::Vec3;

namespace {
const std::vector<Vec3> kL{Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(3, 0, 2)};  // 2 up z, then 3 along x
}

TEST(Polyline, BesideASegment) {
  for (auto ends : {PolylineEnds::kClamped, PolylineEnds::kExtended}) {
    const auto c = closest_on_polyline(kL, Vec3(0.3, 0.4, 1.0), ends);
    EXPECT_LT((c.foot - Vec3(0, 0, 1)).norm(), 1e-15);
    EXPECT_LT((c.tangent - Vec3(0, 0, 1)).norm(), 1e-15);
    EXPECT_DOUBLE_EQ(c.s, 1.0);
    EXPECT_DOUBLE_EQ(c.distance, 0.5);
    EXPECT_TRUE(c.inside);
    const auto d = closest_on_polyline(kL, Vec3(2.0, 0.0, 2.5), ends);  // above the second segment
    EXPECT_LT((d.foot - Vec3(2, 0, 2)).norm(), 1e-15);
    EXPECT_DOUBLE_EQ(d.s, 4.0);  // 2 + 2
    EXPECT_DOUBLE_EQ(d.distance, 0.5);
  }
}

TEST(Polyline, AtTheCornerTheEarlierSegmentWins) {
  // outside the corner (x < 0, z > 2): both segments' closest point is the vertex (0, 0, 2)
  const auto c = closest_on_polyline(kL, Vec3(-0.3, 0.0, 2.4), PolylineEnds::kClamped);
  EXPECT_LT((c.foot - Vec3(0, 0, 2)).norm(), 1e-15);
  EXPECT_LT((c.tangent - Vec3(0, 0, 1)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(c.distance, 0.5);
  EXPECT_FALSE(c.inside);
}

TEST(Polyline, BeyondTheEnds) {
  const Vec3 below(0.0, 0.6, -0.8), beyond(4.0, 0.3, 2.0);
  const auto c0 = closest_on_polyline(kL, below, PolylineEnds::kClamped);  // the first end point: a sphere
  EXPECT_LT((c0.foot - Vec3(0, 0, 0)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(c0.distance, 1.0);
  EXPECT_DOUBLE_EQ(c0.s, 0.0);
  EXPECT_FALSE(c0.inside);
  const auto e0 = closest_on_polyline(kL, below, PolylineEnds::kExtended);  // the first segment goes on
  EXPECT_LT((e0.foot - Vec3(0, 0, -0.8)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(e0.distance, 0.6);
  EXPECT_DOUBLE_EQ(e0.s, -0.8);
  EXPECT_TRUE(e0.inside);
  const auto c1 = closest_on_polyline(kL, beyond, PolylineEnds::kClamped);
  EXPECT_LT((c1.foot - Vec3(3, 0, 2)).norm(), 1e-15);
  EXPECT_NEAR(c1.distance, std::hypot(1.0, 0.3), 1e-15);
  const auto e1 = closest_on_polyline(kL, beyond, PolylineEnds::kExtended);
  EXPECT_LT((e1.foot - Vec3(4, 0, 2)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(e1.s, 6.0);  // 2 + 3 + 1
  EXPECT_DOUBLE_EQ(e1.distance, 0.3);
}

TEST(Polyline, BadPolylines) {
  EXPECT_THROW(closest_on_polyline({Vec3::Zero()}, Vec3::Zero(), PolylineEnds::kClamped), std::invalid_argument);
  const std::vector<Vec3> repeated{Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 1)};
  EXPECT_THROW(closest_on_polyline(repeated, Vec3(1, 0, 0.5), PolylineEnds::kClamped), std::invalid_argument);
  // an axis skips a repeated point
  EXPECT_DOUBLE_EQ(closest_on_polyline(repeated, Vec3(1, 0, 0.5), PolylineEnds::kExtended).distance, 1.0);
}
