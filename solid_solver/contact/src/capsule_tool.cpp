#include "angio/contact/capsule_tool.hpp"

#include "angio/geometry/polyline.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace angio::contact {

AxisDistance polyline_distance(const std::vector<Vec3>& axis, const Vec3& x) {
  const auto c = geometry::closest_on_polyline(axis, x, geometry::PolylineEnds::kClamped);
  AxisDistance best;
  best.foot = c.foot;
  best.r = c.distance;
  if (best.r > 0.0) best.e_r = (x - best.foot) / best.r;
  // beside a segment the foot slides along it (a cylinder), at a vertex or an end it stays (a sphere)
  best.P = c.inside ? Mat3(Mat3::Identity() - c.tangent * c.tangent.transpose()) : Mat3(Mat3::Identity());
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
