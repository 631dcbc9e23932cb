// Flat Eigen vectors of 3-vectors per sample point (coupler internals).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "angio/participant/types.hpp"

namespace angio::coupler {

inline Eigen::VectorXd flatten(const std::vector<participant::Vec3>& v) {
  Eigen::VectorXd out(3 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) out[3 * i + d] = v[i][d];
  return out;
}

inline std::vector<participant::Vec3> unflatten(const Eigen::VectorXd& x) {
  std::vector<participant::Vec3> out(x.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
  return out;
}

}  // namespace angio::coupler
