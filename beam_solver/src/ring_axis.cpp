#include "angio/beam/ring_axis.hpp"

#include <algorithm>
#include <limits>

namespace angio::beam {

std::optional<Axis> ring_centroid_axis(const std::vector<std::vector<int>>& ring_crowns, const std::vector<Vec3>& x) {
  if (ring_crowns.size() < 2) return std::nullopt;
  Axis a;
  a.points.clear();
  for (const auto& ring : ring_crowns) {
    if (ring.empty()) return std::nullopt;
    Vec3 c = Vec3::Zero();
    for (int n : ring) c += x.at(n);
    a.points.push_back(c / double(ring.size()));
  }
  return a;
}

double mean_diameter(const Axis& axis, const std::vector<Vec3>& x, const std::vector<int>& nodes) {
  double s = 0;
  if (nodes.empty()) {
    for (const auto& p : x) s += axis.project(p).r;
    return x.empty() ? 0.0 : 2.0 * s / double(x.size());
  }
  for (int n : nodes) s += axis.project(x.at(n)).r;
  return 2.0 * s / double(nodes.size());
}

double length_along(const Axis& axis, const std::vector<Vec3>& x) {
  if (x.empty()) return 0.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : x) {
    const double s = axis.project(p).s;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  return hi - lo;
}

}  // namespace angio::beam
