// Linear fixed-point maps q -> A q + b for the tests of the interface quasi-Newton methods, and
// one load step of an acceleration on them.
#pragma once

#include <Eigen/Dense>
#include <vector>

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

// `updates` updates of one step on the map extended by a component the map does not respond to
// (its residual is 0 always, as the robin scheme's contact plane out of the stent's reach) and that
// is set to `jump` before the second update, as a plane that appears at the edge of the search
// radius is; with `mark` the acceleration is told (mark_discontinuous). The step is accepted.
// Returns the iterates before each update (7 components, the free one last).
inline std::vector<Eigen::VectorXd> iterates_with_appearing_component(Acceleration& acc, const LinearMap& m,
                                                                      const Eigen::VectorXd& b, double jump, bool mark,
                                                                      int updates) {
  const Eigen::Index n = m.A.rows();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n + 1);
  std::vector<Eigen::VectorXd> out;
  acc.begin_step();
  for (int k = 0; k < updates; ++k) {
    if (k == 1) {
      q[n] = jump;
      if (mark) acc.mark_discontinuous({n});
    }
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n + 1);
    r.head(n) = m.A * q.head(n) + b - q.head(n);
    out.push_back(q);
    q = acc.update(q, r, k);
  }
  acc.end_step(true);
  return out;
}

}  // namespace angio::coupler::testing
