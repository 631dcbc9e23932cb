// Bow of a device axis from three cross-section centroids (one end, the middle, the other end):
// the measure of the post-stenting straightening of a curved device (paper §3.2, Fig. 7).
//   sagitta h: distance of the middle centroid from the chord through the end centroids;
//   radius R:  radius of the circle through the three points, R = |a||b||a − b| / (2|a × b|) with
//              a, b the end centroids relative to the middle one (circumradius of the triangle);
//              infinite for collinear points (a straight device).
// A device that straightens shows a falling h and a growing R.
#pragma once

#include <array>
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

// The bow of each half of a generated stent from its ring centroids c_k (rings in order: the
// points of ring_centroid_axis): half 0 through c_0, c_q, c_mid and half 1 through c_mid,
// c_(n-1-q), c_(n-1), with q = (n-1)/4 and c_mid the middle ring's centroid (the mean of the two
// middle rings' for even n). The whole-device bow (stent_axis_bow) cannot tell a device that
// straightens in its halves but kinks where it is held (the curved free expansion's middle-ring
// fixation) from one that keeps its curvature; the halves can. NaN below 5 rings.
std::array<AxisBow, 2> stent_half_bows(const std::vector<Vec3>& ring_centroids);

}  // namespace angio::beam
