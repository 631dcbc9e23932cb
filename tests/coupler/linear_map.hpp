// Linear fixed-point maps q -> A q + b for the tests of the interface quasi-Newton methods, and
// one load step of an acceleration on them.
#pragma once

#include <Eigen/Dense>

#include "angio/coupler/acceleration.hpp"

namespace angio::coupler::testing {

// A map whose Gauss–Seidel iteration diverges in several modes of both signs (eigenvalues
// −6, −2, 3, 0.5, −0.9, 4), rotated so that the modes are not the unit vectors.
struct LinearMap {
  Eigen::MatrixXd A;
  LinearMap() {
    const int n = 6;
    Eigen::VectorXd lambda(n);
    lambda << -6.0, -2.0, 3.0, 0.5, -0.9, 4.0;
    Eigen::MatrixXd M = Eigen::MatrixXd::Random(n, n);
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(M);
    Eigen::MatrixXd Q = qr.householderQ();
    A = Q * lambda.asDiagonal() * Q.transpose();
  }
  Eigen::VectorXd fixed_point(const Eigen::VectorXd& b) const {
    return (Eigen::MatrixXd::Identity(A.rows(), A.cols()) - A).lu().solve(b);
  }
};

// Runs one step; returns the number of updates until ||r|| <= tol (or -1 after max_updates).
inline int run_step(angio::coupler::Acceleration& acc, const LinearMap& m, const Eigen::VectorXd& b, Eigen::VectorXd& q,
                    int max_updates, double tol = 1e-10) {
  acc.begin_step();
  for (int k = 0; k <= max_updates; ++k) {
    const Eigen::VectorXd r = m.A * q + b - q;
    if (r.norm() <= tol) {
      acc.end_step(true);
      return k;
    }
    if (k == max_updates) break;
    q = acc.update(q, r, k);
  }
  acc.end_step(false);
  return -1;
}

}  // namespace angio::coupler::testing
