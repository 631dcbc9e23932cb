#include "angio/beam/axis_bow.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace angio::beam {

AxisBow axis_bow(const Vec3& end0, const Vec3& middle, const Vec3& end1) {
  AxisBow b;
  const Vec3 chord = end1 - end0;
  b.chord = chord.norm();
  const Vec3 a = end0 - middle, c = end1 - middle;
  const double cross = a.cross(c).norm();  // = chord · sagitta
  b.sagitta = b.chord > 0 ? cross / b.chord : a.norm();
  b.radius = cross > 1e-12 * a.norm() * c.norm() ? a.norm() * c.norm() * b.chord / (2.0 * cross)
                                                 : std::numeric_limits<double>::infinity();
  return b;
}

AxisBow stent_axis_bow(const std::vector<Vec3>& distal, const std::vector<double>& distal_s,
                       const std::vector<Vec3>& central) {
  if (distal.size() != distal_s.size()) throw std::invalid_argument("stent_axis_bow: one arc length per end crown");
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (distal.empty() || central.empty()) return {nan, nan, nan};
  const auto [lo, hi] = std::minmax_element(distal_s.begin(), distal_s.end());
  const double s_mid = 0.5 * (*lo + *hi);
  Vec3 c[2] = {Vec3::Zero(), Vec3::Zero()};
  int count[2] = {0, 0};
  for (std::size_t i = 0; i < distal.size(); ++i) {
    const int side = distal_s[i] < s_mid ? 0 : 1;
    c[side] += distal[i];
    ++count[side];
  }
  if (count[0] == 0 || count[1] == 0) return {nan, nan, nan};  // a single ring has one end
  Vec3 mid = Vec3::Zero();
  for (const auto& x : central) mid += x;
  return axis_bow(c[0] / count[0], mid / double(central.size()), c[1] / count[1]);
}

std::array<AxisBow, 2> stent_half_bows(const std::vector<Vec3>& c) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  const int n = int(c.size());
  if (n < 5) return {AxisBow{nan, nan, nan}, AxisBow{nan, nan, nan}};
  const Vec3 mid = 0.5 * (c[(n - 1) / 2] + c[n / 2]);
  const int q = (n - 1) / 4;
  return {axis_bow(c[0], c[q], mid), axis_bow(mid, c[n - 1 - q], c[n - 1])};
}

}  // namespace angio::beam
