// Aitken relaxation: on a linear fixed-point map q -> A q + b its secant update reaches the
// fixed point in two updates for a scalar map (exact property of the method); factors follow
// docs/design.md §5.4 at the first iteration of a step.
#include <gtest/gtest.h>

#include "angio/coupler/aitken.hpp"

using angio::coupler::Aitken;

TEST(Aitken, ScalarLinearMapConvergesAfterTwoUpdates) {
  // q~ = a q + b with a = −5 (Gauss–Seidel alone diverges); fixed point q* = b/(1 − a).
  const double a = -5.0, b = 3.0, q_star = b / (1.0 - a);
  Aitken acc(0.1, 1.0);
  acc.begin_step();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(1);
  for (int k = 0; k < 2; ++k) {
    Eigen::VectorXd r = (a * q.array() + b).matrix() - q;
    q = acc.update(q, r, k);
  }
  EXPECT_NEAR(q[0], q_star, 1e-12);
}

TEST(Aitken, ComponentMarkedDiscontinuousStaysOutOfTheFactor) {
  // The scalar map of the test above plus a component whose residual drops from 0.5 to 0 at the
  // second update (a contact plane that vanished): marked, the second factor is the scalar map's
  // own (the map's exact secant, so the scalar component reaches the fixed point); unmarked, the
  // vanished residual enters the secant and the factor is wrong.
  const double a = -5.0, b = 3.0, q_star = b / (1.0 - a);
  for (const bool mark : {true, false}) {
    Aitken acc(0.1, 1.0);
    acc.begin_step();
    Eigen::VectorXd q = Eigen::VectorXd::Zero(2);
    for (int k = 0; k < 2; ++k) {
      Eigen::VectorXd r(2);
      r << a * q[0] + b - q[0], k == 0 ? 0.5 : 0.0;
      if (k == 1 && mark) acc.mark_discontinuous({1});
      q = acc.update(q, r, k);
    }
    if (mark)
      EXPECT_NEAR(q[0], q_star, 1e-12);
    else
      EXPECT_GT(std::abs(q[0] - q_star), 1e-3);
  }
}

TEST(Aitken, FirstFactorOfAStepFollowsTheDesign) {
  Aitken acc(0.5, 2.0);
  acc.begin_step();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(1), r = Eigen::VectorXd::Ones(1);
  acc.update(q, r, 0);
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.5);  // ω_0 at the very first step
  Eigen::VectorXd r2 = Eigen::VectorXd::Constant(1, 0.8);
  acc.update(q, r2, 1);  // ω_1 = −0.5·1·(−0.2)/0.04 = 2.5 → capped at 2
  EXPECT_DOUBLE_EQ(acc.last_factor(), 2.0);
  acc.end_step(true);
  acc.begin_step();
  acc.update(q, r, 0);
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.5);  // min(ω_0, |ω_prev|) = min(0.5, 2)
}
