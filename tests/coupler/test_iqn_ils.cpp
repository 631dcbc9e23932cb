// IQN-ILS on linear fixed-point maps q -> A q + b. Exact properties of the method (Degroote et
// al. 2009): with all columns kept it terminates in at most n + 1 updates for an n-dimensional
// linear map (the least-squares model becomes the exact inverse Jacobian once n independent
// differences are known), and with the columns of an earlier step of the same map it hits the
// fixed point with the first update of the next step.
#include <gtest/gtest.h>

#include "angio/coupler/aitken.hpp"
#include "angio/coupler/iqn_ils.hpp"

using angio::coupler::Aitken;
using angio::coupler::IqnIls;
using angio::coupler::IqnIlsOptions;

namespace {

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
int run_step(angio::coupler::Acceleration& acc, const LinearMap& m, const Eigen::VectorXd& b,
             Eigen::VectorXd& q, int max_updates, double tol = 1e-10) {
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

}  // namespace

TEST(IqnIls, LinearMapTerminatesInAtMostNPlusOneUpdates) {
  LinearMap m;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  IqnIls acc(IqnIlsOptions{0.1, 0, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  const int updates = run_step(acc, m, b, q, 7, 1e-9);
  ASSERT_GE(updates, 0) << "IQN-ILS did not terminate on a 6-dimensional linear map";
  EXPECT_LE(updates, 7);
  EXPECT_LT((q - m.fixed_point(b)).norm(), 1e-8);
}

TEST(IqnIls, AitkenCannotHandleModesOfBothSigns) {
  // The comparison that motivates IQN-ILS: one scalar factor cannot relax modes −6 and +4 at once.
  LinearMap m;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  Aitken acc(0.1, 1.0);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  EXPECT_EQ(run_step(acc, m, b, q, 30), -1);
}

TEST(IqnIls, ReusedColumnsSolveTheNextStepWithTheFirstUpdate) {
  LinearMap m;
  IqnIls acc(IqnIlsOptions{0.1, 4, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  ASSERT_GE(run_step(acc, m, Eigen::VectorXd::Ones(6), q, 10, 1e-9), 0);
  const Eigen::VectorXd b2 = Eigen::VectorXd::LinSpaced(6, -1.0, 3.0);  // next load step
  const int updates = run_step(acc, m, b2, q, 10, 1e-8);
  EXPECT_EQ(updates, 1);
  EXPECT_LT((q - m.fixed_point(b2)).norm(), 1e-7);
}

TEST(IqnIls, RejectedStepDiscardsItsColumns) {
  LinearMap m;
  IqnIls acc(IqnIlsOptions{0.25, 4, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  EXPECT_EQ(run_step(acc, m, Eigen::VectorXd::Ones(6), q, 3), -1);  // rejected after 3 updates
  acc.begin_step();
  q = acc.update(q, Eigen::VectorXd::Ones(6), 0);
  EXPECT_EQ(acc.last_columns(), 0);  // nothing from the rejected attempt is reused
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.25);
}

TEST(IqnIls, DependentColumnsAreFilteredWithoutBreakdown) {
  // A scalar problem embedded in 3 components: after the first difference every further one is
  // parallel to it. The filter must drop them instead of solving a singular system.
  IqnIls acc(IqnIlsOptions{0.5, 8, 100, 1e-2});
  const double a = -3.0, b = 1.0;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  for (int step = 0; step < 3; ++step) {
    acc.begin_step();
    for (int k = 0; k < 4; ++k) {
      const Eigen::VectorXd r = (a * q.array() + b).matrix() - q;
      if (r.norm() < 1e-12) break;
      q = acc.update(q, r, k);
      ASSERT_TRUE(q.allFinite());
      EXPECT_LE(acc.last_columns(), 1);
    }
    acc.end_step(true);
  }
  EXPECT_NEAR(q[0], b / (1.0 - a), 1e-12);
}
