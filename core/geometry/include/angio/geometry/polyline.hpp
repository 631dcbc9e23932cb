// Closest point of a polyline: the one computation behind the beam's device axis (radial
// fixation, radial loads, ring diameters) and the solid's virtual insertion tool (a capsule).
// Units: whatever the points are given in (mm).
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace angio::geometry {

using Vec3 = Eigen::Vector3d;

struct PolylinePoint {
  Vec3 foot = Vec3::Zero();      // closest point
  Vec3 tangent = Vec3::UnitZ();  // unit direction of its segment
  double s = 0.0;                // arc length of the foot from the first point (< 0 or > length beyond the ends)
  double distance = 0.0;         // |x − foot|
  bool inside = false;           // the foot lies strictly inside a segment (not at a vertex or an end)
};

// How the ends are treated: kClamped, the polyline ends at its end points (a capsule's end caps);
// kExtended, its first and last segments go on beyond them (an axis longer than its points).
enum class PolylineEnds { kClamped, kExtended };

// Closest point to x over the segments (>= 2 points). Segments of zero length are skipped (with
// kClamped they throw std::invalid_argument: a capsule must not have them). Ties (within 1e-14)
// go to the earlier segment.
PolylinePoint closest_on_polyline(const std::vector<Vec3>& points, const Vec3& x, PolylineEnds ends);

}  // namespace angio::geometry
