// Viscous branch of media and intima (paper eqs. B.5–B.8): kernel against the analytic solution of
// the evolution equation, time convergence order, the part of S∞ it acts on (acts_on: isotropic, the
// 4C default, or all) against closed-form relaxation, and the element tangent against finite differences.
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

// Where the overstress acts (ViscousBranch::acts_on). A strain held from t = 0 (instantaneous step
// Δt = 0 from the stress-free state, then steps of Δt) has the closed-form response
//     S(t) = S∞(C) + β e^(−t/τ) Sv(C),
// Sv = S_iso (Neo-Hooke matrix alone, the default, as 4C's VISCO_GenMax) or Sv = S∞ (acts_on all).
// (a) A fiber-only material (matrix E = 0) stretched along its fiber: with acts_on isotropic nothing
// relaxes (Q ≡ 0, S = S∞ at all times); with acts_on all the fiber stress relaxes from (1 + β) S∞.
// (b) Matrix and fibers under a general held C: the overstress is β e^(−t/τ) times the stress of the
// chosen part, the fiber stress never relaxes under the default.
TEST(Viscous, HeldStrainRelaxesOnlyThePartTheBranchActsOn) {
  EXPECT_EQ(ViscousBranch{}.acts_on, ViscousActsOn::isotropic);  // 4C's placement is the default
  const double tau = 0.5, beta = 0.3, dt = 0.1;
  const FiberFamily fiber{0.5, 2.0, Vec3d::UnitX(), true};
  auto run = [&](const NeoHooke& m, const Mat3& C, ViscousActsOn on, const Vec6& Sv_expected) {
    Mat3 S_inf;
    stress_tangent(m, {fiber}, C, S_inf, nullptr);
    const Vec6 s_inf = to_voigt_stress(S_inf);
    ASSERT_GT(s_inf.norm(), 1e-3);
    const ViscousBranch v{tau, beta, on};
    Vec6 Q = Vec6::Zero(), Sv = Vec6::Zero();
    for (int n = 0; n <= 20; ++n) {
      const double t = n * dt, step = n == 0 ? 0.0 : dt;  // n = 0: the instantaneous response
      Mat3 S;
      Vec6 Q_new, Sv_new;
      viscous_stress_tangent(m, {fiber}, v, step, Q, Sv, C, S, nullptr, Q_new, Sv_new);
      Q = Q_new;
      Sv = Sv_new;
      EXPECT_LT((Sv - Sv_expected).norm(), 1e-14 * s_inf.norm());
      const Vec6 exact = s_inf + beta * std::exp(-t / tau) * Sv_expected;
      EXPECT_LT((to_voigt_stress(S) - exact).norm(), 1e-13 * s_inf.norm()) << to_string(on) << " t " << t;
      EXPECT_LT((Q - beta * std::exp(-t / tau) * Sv_expected).norm(), 1e-13 * s_inf.norm());
    }
  };
  // (a) fiber-only stretch: C = diag(λ², 1, 1) along the fiber, no matrix
  const NeoHooke no_matrix{0.0, 0.0};
  Mat3 C = Mat3::Identity();
  C(0, 0) = 1.1 * 1.1;
  Mat3 S_fib;
  stress_tangent(no_matrix, {fiber}, C, S_fib, nullptr);
  run(no_matrix, C, ViscousActsOn::isotropic, Vec6::Zero());  // Q ≡ 0: no relaxation
  run(no_matrix, C, ViscousActsOn::all, to_voigt_stress(S_fib));
  // (b) matrix and fibers, general C
  const NeoHooke matrix{1.0, 0.45};
  Mat3 F;
  F << 1.12, 0.05, -0.02, 0.03, 0.96, 0.04, -0.01, 0.02, 0.98;
  C = F.transpose() * F;
  Mat3 S_iso, S_all;
  stress_tangent(matrix, {}, C, S_iso, nullptr);
  stress_tangent(matrix, {fiber}, C, S_all, nullptr);
  run(matrix, C, ViscousActsOn::isotropic, to_voigt_stress(S_iso));
  run(matrix, C, ViscousActsOn::all, to_voigt_stress(S_all));
}

// Element tangent with a non-zero viscous history vs finite differences of the internal force
// (hex8, tet4, tet10; the branch on the isotropic part and on all of S∞, fibers in tension), and
// S = S∞ + Q visible in the force: with β = 0 and Q_n = 0 the viscous element equals the elastic
// one; the two placements give different forces.
TEST(Viscous, ElementTangentMatchesFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.08, 0.08);
  Frame fr;
  for (ViscousActsOn on : {ViscousActsOn::isotropic, ViscousActsOn::all}) {
    const LayerMaterial media{"media", {1.0, 0.45}, {{0.5, 2.0, 0.0, true}}, ViscousBranch{0.5, 0.3, on}};
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
      EXPECT_LT((K - Kfd).norm(), 1e-6 * K.norm()) << name(t) << " acts_on " << to_string(on);

      // the other placement, same history: a different force (the fibers are stretched)
      ViscousHistory ho = h;
      ho.branch.acts_on = on == ViscousActsOn::all ? ViscousActsOn::isotropic : ViscousActsOn::all;
      Eigen::VectorXd fo;
      element_internal(t, X, u, media.matrix, fibers, fo, nullptr, nullptr, &ho);
      EXPECT_GT((fo - f).norm(), 1e-3 * f.norm()) << name(t);

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
}
