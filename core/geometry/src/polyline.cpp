#include "angio/geometry/polyline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace angio::geometry {

PolylinePoint closest_on_polyline(const std::vector<Vec3>& points, const Vec3& x, PolylineEnds ends) {
  if (points.size() < 2) throw std::invalid_argument("closest_on_polyline: a polyline needs at least 2 points");
  const bool extended = ends == PolylineEnds::kExtended;
  const int ns = static_cast<int>(points.size()) - 1;
  PolylinePoint best;
  double best_d = std::numeric_limits<double>::infinity(), s0 = 0.0;
  for (int i = 0; i < ns; ++i) {
    const Vec3 d = points[i + 1] - points[i];
    const double L2 = d.squaredNorm();
    if (!(L2 > 0.0)) {
      if (!extended) throw std::invalid_argument("closest_on_polyline: a segment of zero length");
      continue;
    }
    const double L = std::sqrt(L2);
    double t = (x - points[i]).dot(d) / L2;
    const bool inside = t > 0.0 && t < 1.0;
    // the end segments of an extended polyline go on beyond its ends
    if (!(extended && i == 0)) t = std::max(t, 0.0);
    if (!(extended && i == ns - 1)) t = std::min(t, 1.0);
    const Vec3 foot = points[i] + t * d;
    const double dist = (x - foot).norm();
    if (dist < best_d - 1e-14) {  // a tie (e.g. at a vertex) keeps the earlier segment
      best_d = dist;
      best.foot = foot;
      best.tangent = d / L;
      best.s = s0 + t * L;
      best.inside = inside || (extended && ((i == 0 && t <= 0.0) || (i == ns - 1 && t >= 1.0)));
    }
    s0 += L;
  }
  best.distance = best_d;
  return best;
}

}  // namespace angio::geometry
