#include "angio/solid/load_direction.hpp"

#include <algorithm>
#include <cmath>

namespace angio::solid {

namespace {
// −1, 0 or +1: the direction of a change from a to b, none below round-off of the levels' magnitude
int direction(double a, double b, double magnitude) {
  const double d = b - a;
  if (std::abs(d) <= 1e-12 * magnitude) return 0;
  return d > 0.0 ? 1 : -1;
}
}  // namespace

bool loads_keep_direction(const std::vector<double>& before, const std::vector<double>& committed,
                          const std::vector<double>& now) {
  if (before.size() != committed.size() || now.size() != committed.size()) return false;
  for (size_t i = 0; i < now.size(); ++i) {
    const double m = std::max({std::abs(before[i]), std::abs(committed[i]), std::abs(now[i]), 1e-300});
    if (direction(before[i], committed[i], m) != direction(committed[i], now[i], m)) return false;
  }
  return true;
}

}  // namespace angio::solid
