// IQN-IMVJ on linear fixed-point maps q -> A q + b (linear_map.hpp). Properties of the method
// (Bogaers et al. 2014; Lindner, Mehl & Uekermann 2017): without a carried Jacobian it is IQN-ILS
// without reuse, iterate for iterate; once a step has made its inverse Jacobian exact, the next
// step of the same map ends with its first update; and over a ramp of steps it needs far fewer
// updates than IQN-ILS without reuse, which starts from nothing every step.
#include <gtest/gtest.h>

#include "angio/coupler/iqn_ils.hpp"
#include "angio/coupler/iqn_imvj.hpp"
#include "linear_map.hpp"

using angio::coupler::IqnIls;
using angio::coupler::IqnIlsOptions;
using angio::coupler::IqnImvj;
using angio::coupler::testing::LinearMap;
using angio::coupler::testing::run_step;

TEST(IqnImvj, WithoutCarriedJacobianItIsIqnIls) {
  LinearMap m;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  IqnIls ils(IqnIlsOptions{0.1, 0, 100, 1e-10});
  IqnImvj mvj(IqnIlsOptions{0.1, 4, 100, 1e-10});
  ils.begin_step();
  mvj.begin_step();
  Eigen::VectorXd q1 = Eigen::VectorXd::Zero(6), q2 = q1;
  for (int k = 0; k < 7; ++k) {
    const Eigen::VectorXd r1 = m.A * q1 + b - q1, r2 = m.A * q2 + b - q2;
    if (r1.norm() < 1e-9) break;
    q1 = ils.update(q1, r1, k);
    q2 = mvj.update(q2, r2, k);
    EXPECT_LT((q1 - q2).norm(), 1e-10 * (1.0 + q1.norm())) << "update " << k;
  }
  EXPECT_LT((q2 - m.fixed_point(b)).norm(), 1e-8);
}

TEST(IqnImvj, ComponentMarkedDiscontinuousStaysOutOfTheModel) {
  // as IqnIls.ComponentMarkedDiscontinuousStaysOutOfTheModel, over two steps: the carried Jacobian
  // of the first does not move the component in the second either
  LinearMap m;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  const IqnIlsOptions o{0.1, 4, 100, 1e-10};
  IqnImvj marked(o), unmarked(o), plain(o);
  for (int step = 0; step < 2; ++step) {
    const auto with = angio::coupler::testing::iterates_with_appearing_component(marked, m, b, 0.3, true, 6);
    const auto without = angio::coupler::testing::iterates_with_appearing_component(unmarked, m, b, 0.3, false, 6);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
    plain.begin_step();
    for (int k = 0; k < 6; ++k) {
      EXPECT_LT((with[k].head(6) - q).norm(), 1e-12 * (1.0 + q.norm())) << "step " << step << ", update " << k;
      if (k >= 1) {
        EXPECT_EQ(with[k][6], 0.3) << "step " << step << ", update " << k;
      }
      q = plain.update(q, m.A * q + b - q, k);
    }
    plain.end_step(true);
    EXPECT_GT(std::abs(without[2][6] - 0.3), 1e-3) << "step " << step;
  }
}

TEST(IqnImvj, CarriedJacobianSolvesTheNextStepWithTheFirstUpdate) {
  LinearMap m;
  IqnImvj acc(IqnIlsOptions{0.1, 4, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  ASSERT_GE(run_step(acc, m, Eigen::VectorXd::Ones(6), q, 10, 1e-9), 0);
  EXPECT_EQ(acc.carried_steps(), 1);
  const Eigen::VectorXd b2 = Eigen::VectorXd::LinSpaced(6, -1.0, 3.0);  // next load step
  const int updates = run_step(acc, m, b2, q, 10, 1e-8);
  EXPECT_EQ(updates, 1);
  EXPECT_LT((q - m.fixed_point(b2)).norm(), 1e-7);
}

TEST(IqnImvj, RampOfStepsNeedsFewerUpdatesThanIqnIls) {
  // Ten load steps of a slowly changing b (as a pressure ramp), each from the last one's state:
  // IQN-ILS without reuse starts from nothing in every step (measured 7 updates each, the map's
  // dimension + 1); IQN-IMVJ carries the Jacobian the steps before built and needs far fewer
  // (measured 16 in all).
  LinearMap m;
  IqnIls ils(IqnIlsOptions{0.1, 0, 100, 1e-10});
  IqnImvj mvj(IqnIlsOptions{0.1, 100, 100, 1e-10});
  const Eigen::VectorXd b0 = Eigen::VectorXd::LinSpaced(6, 1.0, 2.0);
  const Eigen::VectorXd db = Eigen::VectorXd::LinSpaced(6, 0.3, -0.2);
  Eigen::VectorXd q1 = m.fixed_point(b0), q2 = q1;
  int ils_total = 0, mvj_total = 0;
  for (int step = 1; step <= 10; ++step) {
    const Eigen::VectorXd b = b0 + 0.05 * step * db;
    const int u1 = run_step(ils, m, b, q1, 40, 1e-4);
    const int u2 = run_step(mvj, m, b, q2, 40, 1e-4);
    ASSERT_GE(u1, 0) << "IQN-ILS, step " << step;
    ASSERT_GE(u2, 0) << "IQN-IMVJ, step " << step;
    ils_total += u1;
    mvj_total += u2;
  }
  std::printf("10 steps: IQN-ILS without reuse %d updates, IQN-IMVJ %d\n", ils_total, mvj_total);
  EXPECT_LT(mvj_total, ils_total);
}

TEST(IqnImvj, RestartsFromTheLastStepsOwnModelAfterReusedSteps) {
  // Each step another map (A scaled), so that the carried Jacobian never ends a step at once and
  // every accepted step adds a correction: with reused_steps = 2 the carried steps go 1, 2, and the
  // third restarts J_prev from its own model, W R⁻¹ Qᵀ, which satisfies that step's secant
  // equations J v_i = w_i to round-off (a correction kept relative to the dropped Jacobian,
  // (W − J_old V) R⁻¹ Qᵀ, would miss them by J_old v_i).
  const LinearMap m;
  IqnImvj acc(IqnIlsOptions{0.1, 2, 100, 1e-10});
  std::vector<Eigen::VectorXd> v, w;  // the third step's differences of r and of q~ = q + r
  for (int step = 0; step < 3; ++step) {
    const Eigen::MatrixXd A = (1.0 + 0.15 * step) * m.A;
    const Eigen::VectorXd b = Eigen::VectorXd::Constant(6, 1.0 + step);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(6), r_prev, qt_prev;
    v.clear();
    w.clear();
    acc.begin_step();
    bool converged = false;
    for (int k = 0; k <= 20 && !converged; ++k) {
      const Eigen::VectorXd r = A * q + b - q;
      if (r.norm() <= 1e-9) {
        acc.end_step(true);
        converged = true;
        break;
      }
      if (k > 0) {
        v.push_back(r - r_prev);
        w.push_back(q + r - qt_prev);
      }
      r_prev = r;
      qt_prev = q + r;
      q = acc.update(q, r, k);
    }
    ASSERT_TRUE(converged) << "step " << step;
    EXPECT_EQ(acc.carried_steps(), step == 1 ? 2 : 1) << "after step " << step;
  }
  ASSERT_FALSE(v.empty());
  for (std::size_t i = 0; i < v.size(); ++i)
    EXPECT_LT((acc.carried_jacobian_times(v[i]) - w[i]).norm(), 1e-8 * w[i].norm()) << "column " << i;
  acc.restart();
  EXPECT_EQ(acc.carried_steps(), 0);
}

TEST(IqnImvj, RejectedStepAddsNothing) {
  LinearMap m;
  IqnImvj acc(IqnIlsOptions{0.25, 4, 100, 1e-10});
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  EXPECT_EQ(run_step(acc, m, Eigen::VectorXd::Ones(6), q, 3), -1);  // rejected after 3 updates
  EXPECT_EQ(acc.carried_steps(), 0);
  acc.begin_step();
  q = acc.update(q, Eigen::VectorXd::Ones(6), 0);
  EXPECT_EQ(acc.last_columns(), 0);
  EXPECT_DOUBLE_EQ(acc.last_factor(), 0.25);  // nothing known: relaxation
}
