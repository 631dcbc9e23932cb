#include "angio/solid/stress_average.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace angio::solid {
namespace {

// Cell coordinates (each in [0, 2^21)) packed into one key.
std::uint64_t cell_key(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (std::uint64_t(i) << 42) | (std::uint64_t(j) << 21) | std::uint64_t(k);
}

}  // namespace

std::vector<double> ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                                 const std::vector<double>& value, const std::vector<double>& weight, double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("ball_average: the radius must be positive and finite");
  if (value.size() != point.size() || weight.size() != point.size())
    throw std::invalid_argument("ball_average: points, values and weights differ in number");
  std::vector<double> out(centre.size(), std::numeric_limits<double>::quiet_NaN());
  if (point.empty() || centre.empty()) return out;
  Vec3d lo = point[0], hi = point[0];
  for (const auto& c : point) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  if (((hi - lo) / radius).maxCoeff() >= double(std::int64_t(1) << 20))
    throw std::invalid_argument(
        "ball_average: the radius is too small for the extent of the points (over 2^20 cells per direction)");
  // cells of size `radius` from the points' lower corner: a ball lies in its centre's cell's 3×3×3 block
  auto cell = [&](const Vec3d& c) {
    const Vec3d q = ((c - lo) / radius).array().floor();
    return Eigen::Matrix<std::int64_t, 3, 1>(std::int64_t(q(0)), std::int64_t(q(1)), std::int64_t(q(2)));
  };
  const std::int64_t top = std::int64_t(1) << 21;
  std::vector<std::pair<std::uint64_t, int>> sorted(point.size());
  for (std::size_t p = 0; p < point.size(); ++p) {
    const auto q = cell(point[p]);
    sorted[p] = {cell_key(q(0), q(1), q(2)), int(p)};
  }
  std::sort(sorted.begin(), sorted.end());
  const double r2 = radius * radius;
  for (std::size_t c = 0; c < centre.size(); ++c) {
    const auto q = cell(centre[c]);
    double sum = 0.0, w = 0.0;
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          const std::int64_t i = q(0) + di, j = q(1) + dj, k = q(2) + dk;
          if (i < 0 || j < 0 || k < 0 || i >= top || j >= top || k >= top) continue;  // no point there
          const std::uint64_t key = cell_key(i, j, k);
          for (auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, -1));
               it != sorted.end() && it->first == key; ++it) {
            const int p = it->second;
            if ((point[p] - centre[c]).squaredNorm() <= r2) {
              sum += weight[p] * value[p];
              w += weight[p];
            }
          }
        }
    if (w > 0.0) out[c] = sum / w;
  }
  return out;
}

}  // namespace angio::solid
