#include "angio/solid/stress_average.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace angio::solid {
namespace {

// Cell coordinates (each in [0, 2^21)) packed into one key.
std::uint64_t cell_key(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (std::uint64_t(i) << 42) | (std::uint64_t(j) << 21) | std::uint64_t(k);
}

}  // namespace

std::vector<double> ball_average(const std::vector<Vec3d>& centroid, const std::vector<double>& value,
                                 const std::vector<double>& volume, double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("ball_average: the radius must be positive and finite");
  if (value.size() != centroid.size() || volume.size() != centroid.size())
    throw std::invalid_argument("ball_average: centroids, values and volumes differ in number");
  const std::size_t n = centroid.size();
  if (n == 0) return {};
  Vec3d lo = centroid[0];
  for (const auto& c : centroid) lo = lo.cwiseMin(c);
  // cells of size `radius` from the lower corner: a ball around a centroid lies in its cell's 3×3×3 block
  auto cell = [&](const Vec3d& c) {
    const Vec3d q = (c - lo) / radius;
    return Eigen::Matrix<std::int64_t, 3, 1>(std::int64_t(q(0)), std::int64_t(q(1)), std::int64_t(q(2)));
  };
  for (const auto& c : centroid)
    if (((c - lo) / radius).maxCoeff() >= double(std::int64_t(1) << 20))
      throw std::invalid_argument(
          "ball_average: the radius is too small for the extent of the elements (over 2^20 cells per direction)");
  std::vector<std::pair<std::uint64_t, int>> sorted(n);
  for (std::size_t e = 0; e < n; ++e) {
    const auto q = cell(centroid[e]);
    sorted[e] = {cell_key(q(0), q(1), q(2)), int(e)};
  }
  std::sort(sorted.begin(), sorted.end());
  const double r2 = radius * radius;
  std::vector<double> out(n);
  for (std::size_t e = 0; e < n; ++e) {
    const auto q = cell(centroid[e]);
    double sum = 0.0, vol = 0.0;
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          if (q(0) + di < 0 || q(1) + dj < 0 || q(2) + dk < 0) continue;
          const std::uint64_t key = cell_key(q(0) + di, q(1) + dj, q(2) + dk);
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, -1));
          for (; it != sorted.end() && it->first == key; ++it) {
            const int f = it->second;
            if ((centroid[f] - centroid[e]).squaredNorm() <= r2) {
              sum += volume[f] * value[f];
              vol += volume[f];
            }
          }
        }
    out[e] = vol > 0.0 ? sum / vol : value[e];
  }
  return out;
}

}  // namespace angio::solid
