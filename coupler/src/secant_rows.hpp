// Rows left out of a secant difference (Acceleration::mark_discontinuous): components that jumped
// between the difference's two iterates instead of following the map. Coupler internals.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace angio::coupler {

inline void drop_rows(Eigen::VectorXd& difference, const std::vector<Eigen::Index>& rows) {
  for (Eigen::Index i : rows)
    if (i >= 0 && i < difference.size()) difference[i] = 0.0;
}

}  // namespace angio::coupler
