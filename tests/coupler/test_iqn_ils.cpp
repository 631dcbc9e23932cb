// IQN-ILS on linear fixed-point maps q -> A q + b. Exact properties of the method (Degroote et
// al. 2009): with all columns kept it terminates in at most n + 1 updates for an n-dimensional
// linear map (the least-squares model becomes the exact inverse Jacobian once n independent
// differences are known), and with the columns of an earlier step of the same map it hits the
// fixed point with the first update of the next step.
#include <gtest/gtest.h>

#include "angio/coupler/aitken.hpp"
#include "angio/coupler/iqn_ils.hpp"
#include "linear_map.hpp"

using angio::coupler::Aitken;
using angio::coupler::IqnIls;
using angio::coupler::IqnIlsOptions;

using angio::coupler::testing::LinearMap;
using angio::coupler::testing::run_step;

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

TEST(IqnIls, ComponentMarkedDiscontinuousStaysOutOfTheModel) {
  // A component set anew between two updates (a contact plane that appeared) is not the map's
  // response: marked, the model neither moves it nor changes the other components' iterates (the
  // same as without the component, to round-off: its zero rows add exact zeros to every product,
  // and the iterates came out bitwise equal); unmarked, its jump enters the secant column and the
  // next update moves it although its residual is zero (by 0.21 here, of a jump of 0.3).
  LinearMap m;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  const IqnIlsOptions o{0.1, 0, 100, 1e-10};
  IqnIls marked(o), unmarked(o), plain(o);
  const auto with = angio::coupler::testing::iterates_with_appearing_component(marked, m, b, 0.3, true, 6);
  const auto without = angio::coupler::testing::iterates_with_appearing_component(unmarked, m, b, 0.3, false, 6);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  plain.begin_step();
  for (int k = 0; k < 6; ++k) {
    EXPECT_LT((with[k].head(6) - q).norm(), 1e-12 * (1.0 + q.norm())) << "update " << k;
    if (k >= 1) {
      EXPECT_EQ(with[k][6], 0.3) << "update " << k;
    }
    q = plain.update(q, m.A * q + b - q, k);
  }
  EXPECT_GT(std::abs(without[2][6] - 0.3), 1e-3);
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

TEST(IqnIls, VanishingModelStepRestartsWithRelaxation) {
  // Consistency property of the safeguard. The caller moved q back to 0 outside the acceleration
  // (as the robin scheme does for points that just got a plane), so the column pair says that r
  // changes by (1, 0) while q~ changes by the same amount: the model step q~ + W α is exactly the
  // current q, and without the safeguard every later update would return it unchanged.
  IqnIls acc(IqnIlsOptions{0.5, 8, 100, 1e-2});
  acc.begin_step();
  Eigen::VectorXd q = acc.update(Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(1.0, 0.0), 0);
  EXPECT_TRUE(q.isApprox(Eigen::Vector2d(0.5, 0.0)));
  const Eigen::Vector2d r(2.0, 0.0);
  q = acc.update(Eigen::Vector2d(0.0, 0.0), r, 1);
  EXPECT_EQ(acc.restarts(), 1);
  EXPECT_EQ(acc.last_columns(), 0);
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.5);
  EXPECT_TRUE(q.isApprox(0.5 * r)) << q.transpose();
  // After the restart the model learns from genuine differences again: with q~ = (2 + q₀/2, q₁/2)
  // (r = (2, 0) at q = 0 as above, fixed point (4, 0)) one secant step is exact in 1D.
  const Eigen::Vector2d r2(2.0 + 0.5 * q[0] - q[0], 0.5 * q[1] - q[1]);
  q = acc.update(q, r2, 2);
  EXPECT_EQ(acc.restarts(), 1);
  EXPECT_TRUE(q.isApprox(Eigen::Vector2d(4.0, 0.0))) << q.transpose();
}

TEST(IqnIls, RestartDropsTheColumnsOfEarlierStepsToo) {
  // Unlike begin_step() (a new step keeps the reused columns, see
  // ReusedColumnsSolveTheNextStepWithTheFirstUpdate), restart() forgets everything: its first
  // update relaxes with ω₀ and uses no column.
  LinearMap m;
  IqnIls acc(IqnIlsOptions{0.1, 4, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  ASSERT_GE(run_step(acc, m, Eigen::VectorXd::Ones(6), q, 10, 1e-9), 0);
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(6);
  acc.begin_step();
  acc.update(q, r, 0);
  EXPECT_GT(acc.last_columns(), 0);
  acc.restart();
  const Eigen::VectorXd next = acc.update(q, r, 0);
  EXPECT_EQ(acc.last_columns(), 0);
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.1);
  EXPECT_TRUE(next.isApprox(q + 0.1 * r));
}
