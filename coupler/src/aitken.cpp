#include "angio/coupler/aitken.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace angio::coupler {

Aitken::Aitken(double initial, double maximum)
    : initial_(initial), maximum_(maximum), omega_(initial), omega_prev_(initial), omega_step_start_(initial) {
  if (!(initial > 0.0) || !(maximum >= initial))
    throw std::invalid_argument("Aitken: need 0 < initial <= maximum relaxation factor");
}

void Aitken::begin_step() {
  omega_prev_ = omega_step_start_;
  r_prev_.resize(0);
}

Eigen::VectorXd Aitken::update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) {
  const std::vector<Eigen::Index> jumped = take_discontinuous();
  if (k == 0 || r_prev_.size() != r.size()) {
    const double s = omega_prev_ < 0.0 ? -1.0 : 1.0;
    omega_ = s * std::min(initial_, std::abs(omega_prev_));
  } else {
    Eigen::VectorXd dr = r - r_prev_;
    drop_rows(dr, jumped);  // dr's zero rows also take them out of r_prev·dr
    const double dd = dr.squaredNorm();
    // dd == 0: the residual did not change; keep the factor instead of dividing by zero.
    if (dd > 0.0) omega_ = -omega_ * r_prev_.dot(dr) / dd;
    omega_ = std::clamp(omega_, -maximum_, maximum_);
    if (omega_ == 0.0) omega_ = initial_;
  }
  r_prev_ = r;
  return q + omega_ * r;
}

void Aitken::end_step(bool accepted) {
  if (accepted) omega_step_start_ = omega_;
}

}  // namespace angio::coupler
