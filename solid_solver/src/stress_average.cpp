#include "angio/solid/stress_average.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "angio/contact/search.hpp"

namespace angio::solid {

std::vector<double> ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                                 const std::vector<double>& value, const std::vector<double>& weight, double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("ball_average: the radius must be positive and finite");
  if (value.size() != point.size() || weight.size() != point.size())
    throw std::invalid_argument("ball_average: points, values and weights differ in number");
  std::vector<double> out(centre.size(), std::numeric_limits<double>::quiet_NaN());
  if (point.empty() || centre.empty()) return out;
  // the contact search's AABB tree over the points' boxes inflated by the radius: a centre's
  // candidates are the points within the radius along every axis, the exact distance decides
  std::vector<contact::Aabb> boxes(point.size());
  for (std::size_t p = 0; p < point.size(); ++p) {
    boxes[p].extend(point[p]);
    boxes[p].inflate(radius);
  }
  contact::AabbTree tree;
  tree.build(boxes);
  const double r2 = radius * radius;
  std::vector<int> near;
  for (std::size_t c = 0; c < centre.size(); ++c) {
    near.clear();
    tree.query(centre[c], near);
    double sum = 0.0, w = 0.0;
    for (const int p : near)
      if ((point[p] - centre[c]).squaredNorm() <= r2) {
        sum += weight[p] * value[p];
        w += weight[p];
      }
    if (w > 0.0) out[c] = sum / w;
  }
  return out;
}

}  // namespace angio::solid
