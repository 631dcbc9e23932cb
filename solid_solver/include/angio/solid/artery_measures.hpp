// What a user reads from an artery (pure functions, no MPI): volume-weighted stress percentiles per
// layer, the lumen diameter profile along the vessel, and stent apposition. Units: mm, MPa.
#pragma once
#include <limits>
#include <vector>

#include "angio/solid/mesh.hpp"

namespace angio::solid {

// The q-quantile (0 < q ≤ 1) of `values` weighted by `weights` (e.g. element volumes): the smallest
// value v such that the values ≤ v carry at least q of the total weight. Robust against the one element
// of the maximum; where struts press the wall, q's share of the volume may still lie within the singular
// field of the line load (stress_average.hpp), and the quantile then grows under refinement too.
// Empty input: NaN.
double weighted_quantile(std::vector<double> values, std::vector<double> weights, double q);

// Lumen diameter along the vessel: the endothelium nodes grouped into axial stations (the rings of
// a structured tube, or `max_stations` equal bins of an unstructured mesh), the diameter of a station
// being 2 × the mean distance of its nodes from their centroid in the current configuration (the
// centroid follows a vessel that moves or bends).
class LumenProfile {
 public:
  LumenProfile() = default;
  // station: the reference axial coordinate (arc length) of each endothelium node, in the order in
  // which diameters() gets their positions.
  LumenProfile(const std::vector<double>& station, int max_stations);
  const std::vector<double>& stations() const { return s_; }  // mean reference station of each group (mm)
  // x: current positions of the endothelium nodes, in the constructor's order (the lumen's nodes
  // only: a rank holds those, not the whole mesh); centroids (optional): each station's centroid, the
  // deformed lumen centerline a later device is placed on.
  std::vector<double> diameters(const std::vector<Vec3d>& x, std::vector<Vec3d>* centroids = nullptr) const;
  bool empty() const { return groups_.empty(); }

 private:
  std::vector<double> s_;
  std::vector<std::vector<int>> groups_;  // per station: its nodes' positions in the constructor's list
  std::size_t nodes_ = 0;                 // the number of endothelium nodes
};

// Apposition of the stent: gap per strut sample point (distance from the strut surface to the
// endothelium, g = (x − s)·n − R; negative: embedded; +∞: no endothelium within the search radius)
// with its arc-length weight.
struct Apposition {
  double length = 0.0;               // stent centerline length (mm), Σ w
  double malapposed_length = 0.0;    // Σ w over points with g > threshold (or no wall in range)
  double malapposed_fraction = 0.0;  // malapposed_length / length
  double max_gap = -std::numeric_limits<double>::infinity();  // largest finite gap (mm)
  double mean_gap = 0.0;                                      // length-weighted mean of the finite gaps (mm)
};
Apposition apposition(const std::vector<double>& gap, const std::vector<double>& weight, double threshold);

// Lumped nodal area of a surface set (reference configuration): each face's area shared equally by
// its nodes. Returns a vector indexed by mesh node (0 off the surface).
std::vector<double> nodal_areas(const Mesh& mesh, const SurfaceSet& surface);

}  // namespace angio::solid
