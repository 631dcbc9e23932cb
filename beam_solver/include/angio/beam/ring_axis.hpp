// The axis of the deformed stent, and the stent diameter about it and length along it.
// The paper measures the stent diameter as the mean radial distance of the stent nodes from the
// device axis (§3.1). Measured from the fixed reference axis, a device that moves or straightens
// (the curved free expansion, §3.2) shows a diameter that is too large: a ring of radius r whose
// centre sits δ off the reference axis has a mean distance ≈ r(1 + δ²/(4r²)) from it. The axis of
// the deformed stent is the polyline through the centroids of each ring's crowns (the crowns of a
// ring are evenly spread around its circumference, so their centroid lies on the axis), extended
// beyond the end rings as Axis does.
#pragma once

#include <optional>
#include <vector>

#include "angio/beam/model.hpp"

namespace angio::beam {

// Polyline through the centroids of the rings' crowns (`ring_crowns[k]`: node indices of ring k,
// in order along the device) at positions `x`; nullopt for fewer than two rings.
std::optional<Axis> ring_centroid_axis(const std::vector<std::vector<int>>& ring_crowns, const std::vector<Vec3>& x);

// 2 × mean distance of the nodes `nodes` (all nodes when empty) from `axis`.
double mean_diameter(const Axis& axis, const std::vector<Vec3>& x, const std::vector<int>& nodes = {});

// Extent of the nodes' feet along `axis` (max − min arc length of their projections): the device
// length measured along itself, which a rigid motion or a bend does not change.
double length_along(const Axis& axis, const std::vector<Vec3>& x);

}  // namespace angio::beam
