// Bow of a device axis from three cross-section centroids (one end, the middle, the other end):
// the measure of the post-stenting straightening of a curved device (paper §3.2, Fig. 7).
//   sagitta h: distance of the middle centroid from the chord through the end centroids;
//   radius R:  radius of the circle through the three points, R = |a||b||a − b| / (2|a × b|) with
//              a, b the end centroids relative to the middle one (circumradius of the triangle);
//              infinite for collinear points (a straight device).
// A device that straightens shows a falling h and a growing R.
#pragma once

#include <vector>

#include "angio/beam/model.hpp"

namespace angio::beam {

struct AxisBow {
  double chord = 0;    // mm, distance of the end centroids
  double sagitta = 0;  // mm
  double radius = 0;   // mm (infinity when straight)
};

AxisBow axis_bow(const Vec3& end0, const Vec3& middle, const Vec3& end1);

// The bow of a generated stent (StentMesh::distal_nodes / central_nodes): the centroid of each end
// ring's outer crowns (the distal nodes split at the middle of their arc lengths `distal_s` along
// the device axis) and the centroid of the middle crowns. Outer crowns are evenly spread around
// the circumference, so each end centroid lies on the axis. NaN when there are not two ends
// (a single ring).
AxisBow stent_axis_bow(const std::vector<Vec3>& distal, const std::vector<double>& distal_s,
                       const std::vector<Vec3>& central);

}  // namespace angio::beam
