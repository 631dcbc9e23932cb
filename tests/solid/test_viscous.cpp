// Viscous branch of media and intima (paper eqs. B.5–B.8): kernel against the analytic solution of
// the evolution equation, time convergence order, and the element tangent against finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "angio/solid/elements.hpp"
#include "angio/solid/viscous.hpp"
#include "fd_tangent.hpp"

using namespace angio::solid;

namespace {
Vec6 unit11(double v) {
  Vec6 s = Vec6::Zero();
  s(0) = v;
  return s;
}
}  // namespace

// Analytic solution: a constant-rate ramp S∞ = a t up to t1, then held. Q̇ + Q/τ = β a gives
// Q = β a τ (1 − e^(−t/τ)) on the ramp and Q(t1) e^(−(t − t1)/τ) in the relaxation. The update is
// the exact convolution for an S∞ linear over each step, so it matches to round-off for any Δt.
TEST(Viscous, RampAndRelaxationMatchAnalyticSolution) {
  const ViscousBranch v{0.5, 0.3};
  const double a = 2.0, t1 = 0.8;
  auto exact = [&](double t) {
    const double q1 = v.beta * a * v.tau * (1.0 - std::exp(-std::min(t, t1) / v.tau));
    return t <= t1 ? q1 : q1 * std::exp(-(t - t1) / v.tau);
  };
  for (double dt : {0.4, 0.1, 0.02}) {
    Vec6 Q = Vec6::Zero(), S = Vec6::Zero();
    for (int n = 1; n * dt <= 2.0 + 1e-12; ++n) {
      const double t = n * dt;
      const Vec6 S_new = unit11(a * std::min(t, t1));
      Q = viscous_update(v, dt, Q, S, S_new);
      S = S_new;
      EXPECT_NEAR(Q(0), exact(t), 1e-13) << "dt " << dt << " t " << t;
      EXPECT_EQ(Q.tail<5>().norm(), 0.0);
    }
  }
}

// Convergence: for a smooth history S∞ = sin(ω t) the update (piecewise-linear S∞ in time) is a
// second-order scheme; halving Δt divides the error at t = 1 by ≈ 4. Reference: the convolution
// integral Q(t) = β ∫ e^(−(t−s)/τ) Ṡ∞(s) ds in closed form.
TEST(Viscous, SecondOrderForSmoothHistory) {
  const ViscousBranch v{0.5, 0.3};
  const double w = 3.0, T = 1.0;
  // β ω ∫0^T e^(−(T−s)/τ) cos(ω s) ds
  const double k = 1.0 / v.tau;
  const double exact =
      v.beta * w * (k * std::cos(w * T) + w * std::sin(w * T) - k * std::exp(-k * T)) / (k * k + w * w);
  std::vector<double> err;
  for (int n : {20, 40, 80, 160}) {
    const double dt = T / n;
    Vec6 Q = Vec6::Zero(), S = Vec6::Zero();
    for (int i = 1; i <= n; ++i) {
      const Vec6 S_new = unit11(std::sin(w * i * dt));
      Q = viscous_update(v, dt, Q, S, S_new);
      S = S_new;
    }
    err.push_back(std::abs(Q(0) - exact));
  }
  for (size_t i = 1; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    EXPECT_NEAR(order, 2.0, 0.1) << "refinement " << i;
  }
}

// g(ξ) = (1 − e^(−ξ))/ξ is accurate for small ξ (no cancellation) and g(0) = 1 (instantaneous response).
TEST(Viscous, RateFactorLimits) {
  EXPECT_EQ(viscous_rate_factor(0.0), 1.0);
  EXPECT_NEAR(viscous_rate_factor(1e-8), viscous_rate_factor(1.0000001e-8), 1e-15);
  EXPECT_NEAR(viscous_rate_factor(1e-12), 1.0 - 0.5e-12, 1e-16);  // no cancellation near 0
  const double x = 1e-3;  // series reference (the closed form cancels at this ξ)
  EXPECT_NEAR(viscous_rate_factor(x), 1.0 - x / 2 + x * x / 6 - x * x * x / 24 + x * x * x * x / 120, 1e-15);
  EXPECT_NEAR(viscous_rate_factor(50.0), 1.0 / 50.0, 1e-15);
  double factor = 0.0;
  viscous_update({0.5, 0.3}, 0.0, Vec6::Zero(), Vec6::Zero(), unit11(1.0), &factor);
  EXPECT_DOUBLE_EQ(factor, 1.3);
}

// Element tangent with a non-zero viscous history vs finite differences of the internal force
// (hex8, tet4, tet10), and S = S∞ + Q visible in the force: with β = 0 and Q_n = 0 the viscous
// element equals the elastic one.
TEST(Viscous, ElementTangentMatchesFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.08, 0.08);
  Frame fr;
  const LayerMaterial media{"media", {1.0, 0.45}, {{0.5, 2.0, 0.0, true}}, ViscousBranch{0.5, 0.3}};
  const auto fibers = resolve_fibers(media, fr);
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    const auto ref = reference_nodes(t);
    Eigen::MatrixXd X(ref.size(), 3), u(ref.size(), 3);
    for (size_t a = 0; a < ref.size(); ++a) X.row(a) = ref[a].transpose();
    for (int i = 0; i < u.size(); ++i) u.data()[i] = U(rng);
    for (int a = 0; a < X.rows(); ++a) u(a, 0) += 0.2 * X(a, 0);
    const size_t nq = volume_rule(t).size();
    std::vector<Vec6> Qn(nq), Sn(nq);
    for (size_t q = 0; q < nq; ++q) {
      Qn[q] = Vec6::Random() * 0.1;
      Sn[q] = Vec6::Random() * 0.2;
    }
    ViscousHistory h{*media.viscous, 0.1, Qn.data(), Sn.data(), nullptr, nullptr};
    Eigen::VectorXd f;
    Eigen::MatrixXd K;
    ASSERT_TRUE(element_internal(t, X, u, media.matrix, fibers, f, &K, nullptr, &h));
    const Eigen::MatrixXd Kfd = angio_test::fd_tangent(u, [&](const Eigen::MatrixXd& v, Eigen::VectorXd& fv) {
      element_internal(t, X, v, media.matrix, fibers, fv, nullptr, nullptr, &h);
    });
    EXPECT_LT((K - Kfd).norm(), 1e-6 * K.norm()) << name(t);

    // β = 0, no history: identical to the elastic element
    ViscousHistory h0 = h;
    h0.branch.beta = 0.0;
    std::vector<Vec6> zero(nq, Vec6::Zero());
    h0.Q_n = zero.data();
    Eigen::VectorXd f0, fe;
    element_internal(t, X, u, media.matrix, fibers, f0, nullptr, nullptr, &h0);
    element_internal(t, X, u, media.matrix, fibers, fe, nullptr);
    EXPECT_LT((f0 - fe).norm(), 1e-14 * fe.norm()) << name(t);
  }
}
