#include "angio/contact/capsule_tool.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace angio::contact {

AxisDistance polyline_distance(const std::vector<Vec3>& axis, const Vec3& x) {
  if (axis.size() < 2) throw std::invalid_argument("polyline_distance: an axis needs at least 2 points");
  AxisDistance best;
  double best_d2 = std::numeric_limits<double>::infinity();
  bool best_inside = false;
  Vec3 best_t = Vec3::Zero();
  for (std::size_t i = 0; i + 1 < axis.size(); ++i) {
    const Vec3 a = axis[i], d = axis[i + 1] - a;
    const double L2 = d.squaredNorm();
    if (!(L2 > 0.0)) throw std::invalid_argument("polyline_distance: a segment of zero length");
    const double s = (x - a).dot(d) / L2;
    const bool inside = s > 0.0 && s < 1.0;
    const Vec3 foot = a + std::clamp(s, 0.0, 1.0) * d;
    const double d2 = (x - foot).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.foot = foot;
      best_inside = inside;
      best_t = d / std::sqrt(L2);
    }
  }
  best.r = std::sqrt(best_d2);
  if (best.r > 0.0) best.e_r = (x - best.foot) / best.r;
  best.P = best_inside ? Mat3(Mat3::Identity() - best_t * best_t.transpose()) : Mat3(Mat3::Identity());
  return best;
}

ToolNodeContact capsule_node(const AxisDistance& d, double R, double eps_area) {
  ToolNodeContact c;
  const double pen = R - d.r;
  if (!(pen > 0.0)) return c;
  c.active = true;
  c.penetration = pen;
  c.energy = 0.5 * eps_area * pen * pen;
  if (!(d.r > 0.0)) return c;
  const Mat3 ee = d.e_r * d.e_r.transpose();
  c.r = -eps_area * pen * d.e_r;
  c.K = eps_area * (ee - (pen / d.r) * (d.P - ee));
  return c;
}

}  // namespace angio::contact
