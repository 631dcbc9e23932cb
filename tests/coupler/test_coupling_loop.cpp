// The coupling loop against in-process participants with an analytic coupled solution
// (spring_participants.hpp): converged loads equal the analytic fixed point; Aitken converges
// where plain Gauss–Seidel diverges; a participant failure rejects and cuts the step, and the
// participants are rolled back.
#include <gtest/gtest.h>

#include "angio/common/log.hpp"
#include "angio/coupler/aitken.hpp"
#include "angio/coupler/coupling_loop.hpp"
#include "angio/coupler/iqn_ils.hpp"
#include "spring_participants.hpp"

using namespace angio;

namespace {
scene::TimeSettings ramp(int steps) {
  scene::TimeSettings t;
  t.end = 1.0;
  t.steps = steps;
  t.min_step = 1e-3;
  return t;
}

// Runs a ramp of `steps` load steps and returns every accepted step's report (run: the run's totals).
std::vector<coupler::StepReport> run_ramp(test::SpringBeam& beam, test::WallSolid& wall, int steps,
                                          const coupler::CouplingSettings& s, coupler::Acceleration& acc,
                                          coupler::RunReport* run = nullptr) {
  std::vector<coupler::StepReport> reports;
  const coupler::RunReport r = coupler::run_coupled(beam, wall, ramp(steps), s, acc,
                                                    [&](const coupler::StepReport& rep) { reports.push_back(rep); });
  if (run) *run = r;
  return reports;
}

// Analytic fixed point at t = 1 (spring_participants.hpp): q* = eps (s_max − x0 − R) / (1 + eps/kb).
double analytic_q(const test::SpringBeam& beam, const test::WallSolid& wall) {
  return wall.eps * (wall.s_max - beam.x0 - beam.R) / (1.0 + wall.eps / beam.kb);
}
}  // namespace

TEST(CouplingLoop, ConvergesToAnalyticFixedPointWithAitken) {
  test::SpringBeam beam;
  test::WallSolid wall;
  beam.kb = 1.0;
  wall.eps = 10.0;  // stiff: eps/kb = 10, plain Gauss–Seidel would diverge
  coupler::CouplingSettings s;
  s.rel_tol = 1e-10;
  s.abs_tol = 1e-12;
  coupler::Aitken aitken(0.5, 1.0);
  coupler::RunReport run;
  const auto reports = run_ramp(beam, wall, 4, s, aitken, &run);
  ASSERT_EQ(run.steps, 4);
  const double q_star = analytic_q(beam, wall);
  for (double x : beam.x_committed) EXPECT_NEAR(x, 1.0 + q_star / 1.0, 1e-9);
  EXPECT_NEAR(reports.back().contact.line_loads[0][0], q_star, 1e-9);
  // Step 1 crosses the contact kink (the first iterate overshoots into separation, where the map
  // is flat), so it needs many iterations. Once the active set is fixed the map is linear and
  // Aitken's secant step is exact after two residuals; the extrapolated prediction then makes
  // later steps converge at once.
  for (std::size_t i = 1; i < reports.size(); ++i) EXPECT_LE(reports[i].iterations, 3) << "step " << reports[i].step;
}

TEST(CouplingLoop, PlainGaussSeidelFailsOnStiffContact) {
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.eps = 10.0;
  coupler::CouplingSettings s;
  s.max_iterations = 30;
  s.rel_tol = 1e-8;
  coupler::ConstantRelaxation plain(1.0);
  auto t = ramp(2);
  t.min_step = 0.2;  // only one cut allowed
  EXPECT_THROW(coupler::run_coupled(beam, wall, t, s, plain), StepFailure);
  // Everything was rolled back: the beam still sits at its committed state.
  EXPECT_EQ(beam.x, beam.x_committed);
}

TEST(CouplingLoop, ParticipantFailureCutsTheStep) {
  test::SpringBeam beam;
  test::WallSolid wall;
  beam.fail_at_step = 2;
  coupler::CouplingSettings s;
  s.prediction = "constant";  // nothing to fall back to: the failed step is cut
  coupler::Aitken aitken(0.5, 1.0);
  coupler::RunReport run;
  const auto reports = run_ramp(beam, wall, 4, s, aitken, &run);
  EXPECT_EQ(run.rejected_attempts, 1);
  EXPECT_EQ(beam.rejected, 1);
  EXPECT_EQ(reports[1].cuts, 1);
  EXPECT_NEAR(reports[1].time, 0.375, 1e-12);  // half of the 0.25 increment after 0.25
  EXPECT_NEAR(reports.back().time, 1.0, 1e-12);
}

// With the extrapolated first iterate, a participant failure in the first coupling iteration is
// retried once from the last accepted interface state before the step is cut: the step keeps its
// increment, the participants were rolled back once.
TEST(CouplingLoop, FailureFromTheExtrapolatedStartIsRetriedFromTheLastState) {
  test::SpringBeam beam;
  test::WallSolid wall;
  beam.fail_at_step = 2;
  coupler::CouplingSettings s;
  ASSERT_EQ(s.prediction, "extrapolate");
  coupler::Aitken aitken(0.5, 1.0);
  coupler::RunReport run;
  const auto reports = run_ramp(beam, wall, 4, s, aitken, &run);
  EXPECT_EQ(run.prediction_retries, 1);
  EXPECT_EQ(run.rejected_attempts, 0);
  EXPECT_EQ(beam.rejected, 1);
  ASSERT_EQ(reports.size(), 4u);
  EXPECT_EQ(reports[1].cuts, 0);
  EXPECT_NEAR(reports[1].time, 0.5, 1e-12);  // not cut
}

TEST(CouplingLoop, NoContactConvergesInOneIteration) {
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.s_max = 1.0;  // the wall never reaches the beam
  coupler::CouplingSettings s;
  coupler::Aitken aitken(0.5, 1.0);
  auto run = coupler::run_coupled(beam, wall, ramp(3), s, aitken);
  EXPECT_EQ(run.steps, 3);
  EXPECT_EQ(run.max_iterations, 1);
}

TEST(CouplingLoop, RobinSchemeReachesTheSameFixedPointWithExactPlanes) {
  // Robin mode: the beam sees the wall's penalty law itself, so for this planar wall the coupled
  // problem is solved inside the beam; the coupling only has to bring the plane up to date
  // (analytic fixed point as in the Aitken test; exactness of the plane model gives the count).
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.eps = 10.0;
  coupler::CouplingSettings s;
  s.scheme = "robin";
  s.rel_tol = 1e-10;
  s.abs_tol = 1e-12;
  coupler::Aitken aitken(0.5, 1.0);
  coupler::RunReport run;
  const auto reports = run_ramp(beam, wall, 4, s, aitken, &run);
  ASSERT_EQ(run.steps, 4);
  const double q_star = analytic_q(beam, wall);
  for (double x : beam.x_committed) EXPECT_NEAR(x, 1.0 + q_star, 1e-9);
  EXPECT_NEAR(reports.back().contact.line_loads[0][0], q_star, 1e-9);
  // Step 2 starts from step 1's plane: ω_0-relaxed first update, then Aitken's secant step is
  // exact for this linear plane map (≤ 3 iterations). From step 3 on the plane offset is
  // extrapolated from two accepted steps, which is exact for the linear wall ramp: 1 iteration.
  EXPECT_LE(reports[1].iterations, 3);
  for (std::size_t i = 2; i < reports.size(); ++i) EXPECT_EQ(reports[i].iterations, 1) << "step " << reports[i].step;
}

// Consistency and the convergence property the option exists for: a strut against a wall that
// gives way (surface stiffness kw_i = 0.05 .. 0.4 N/mm² per point behind a penalty of 10, a beam of
// 0.1; IQN-ILS without reuse, as the shipped scenes) reaches the analytic fixed point with and
// without surface compliance. Plain planes contract by ~0.96 per iteration at every point at its own
// rate (Aitken's one factor needs more than 200 iterations per step here); with the surface
// compliance the beam sees the series spring of penalty and surface, exact for this local wall:
// from the third step on (the secant of the second is known) a step needs at most 3 iterations,
// and the run at most half of the iterations of the plain planes.
TEST(CouplingLoop, RobinSurfaceComplianceKeepsTheFixedPointAndSavesIterations) {
  auto run = [](bool compliance, std::vector<coupler::StepReport>& reports, test::SpringBeam& beam) {
    test::WallSolid wall;
    wall.eps = 10.0;
    wall.kw = {0.05, 0.1, 0.2, 0.4};
    beam.kb = 0.1;
    coupler::CouplingSettings s;
    s.scheme = "robin";
    s.surface_compliance = compliance;
    s.prediction = "constant";  // extrapolation is exact for this linear ramp and would hide the map
    s.rel_tol = 1e-9;
    s.abs_tol = 1e-12;
    s.max_iterations = 200;
    coupler::IqnIlsOptions o;
    o.reused_steps = 0;
    coupler::IqnIls iqn(o);
    const coupler::RunReport r = coupler::run_coupled(beam, wall, ramp(8), s, iqn,
                                                      [&](const coupler::StepReport& rep) { reports.push_back(rep); });
    EXPECT_EQ(r.steps, 8);
    for (int i = 0; i < beam.n; ++i)
      EXPECT_NEAR(beam.x_committed[i],
                  beam.x0 + wall.eps_series(i) * (wall.s_max - wall.x0 - beam.R) / (beam.kb + wall.eps_series(i)), 1e-7)
          << "point " << i;
    return r.total_iterations;
  };
  std::vector<coupler::StepReport> plain_steps, soft_steps;
  test::SpringBeam plain_beam, soft_beam;
  const int plain = run(false, plain_steps, plain_beam), soft = run(true, soft_steps, soft_beam);
  for (std::size_t i = 2; i < soft_steps.size(); ++i)
    EXPECT_LE(soft_steps[i].iterations, 3) << "step " << soft_steps[i].step;
  EXPECT_LE(2 * soft, plain) << "iterations with surface compliance " << soft << ", without " << plain;
}

// A rejected step is tried again from plain planes (an estimate from a step whose contact set
// changed can be far too soft, and would fail every cut of the step the same way): the beam gets
// softened planes before the failure and the penalty itself in the attempt after it.
TEST(CouplingLoop, RobinSurfaceComplianceStartsAgainFromPlainPlanesAfterARejectedStep) {
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.kw = {0.05, 0.1, 0.2, 0.4};
  beam.kb = 0.1;
  beam.fail_at_step = 5;
  coupler::CouplingSettings s;
  s.scheme = "robin";
  s.surface_compliance = true;
  s.prediction = "constant";  // the failed step is cut, not retried from the last state
  s.rel_tol = 1e-9;
  s.abs_tol = 1e-12;
  coupler::IqnIlsOptions o;
  o.reused_steps = 0;
  coupler::IqnIls iqn(o);
  std::vector<std::size_t> solves_before;  // the beam's solve count at every accepted step
  coupler::RunReport run = coupler::run_coupled(
      beam, wall, ramp(8), s, iqn, [&](const coupler::StepReport&) { solves_before.push_back(beam.plane_eps.size()); });
  ASSERT_EQ(run.rejected_attempts, 1);
  ASSERT_GE(solves_before.size(), 5u);
  // step 4's last solve had a softened plane; the failed attempt of step 5 too (its one solve);
  // the attempt after it starts plain
  EXPECT_LT(beam.plane_eps[solves_before[3] - 1], wall.eps);
  EXPECT_LT(beam.plane_eps[solves_before[3]], wall.eps);
  EXPECT_DOUBLE_EQ(beam.plane_eps[solves_before[3] + 1], wall.eps);
  EXPECT_NEAR(beam.x_committed[0],
              beam.x0 + wall.eps_series(0) * (wall.s_max - wall.x0 - beam.R) / (beam.kb + wall.eps_series(0)), 1e-7);
}

namespace {
// The coupler's debug output of a robin run (IQN-ILS without reuse, tight tolerances) of `steps`
// load steps; every accepted step's report into `reports`.
std::string robin_debug_log(test::SpringBeam& beam, test::WallSolid& wall, int steps, bool surface_compliance,
                            std::vector<coupler::StepReport>& reports) {
  coupler::CouplingSettings s;
  s.scheme = "robin";
  s.surface_compliance = surface_compliance;
  s.rel_tol = 1e-9;
  s.abs_tol = 1e-12;
  coupler::IqnIlsOptions o;
  o.reused_steps = 0;
  coupler::IqnIls iqn(o);
  // the level and the capture are restored even if the run throws, so that later tests see neither
  struct DebugCapture {
    log::Level before = log::level();
    DebugCapture() {
      log::set_level(log::Level::debug);
      testing::internal::CaptureStdout();
    }
    std::string take() {
      taken = true;
      return testing::internal::GetCapturedStdout();
    }
    ~DebugCapture() {
      if (!taken) testing::internal::GetCapturedStdout();
      log::set_level(before);
    }
    bool taken = false;
  } capture;
  coupler::run_coupled(beam, wall, ramp(steps), s, iqn, [&](const coupler::StepReport& r) { reports.push_back(r); });
  return capture.take();
}
}  // namespace

// The debug log names, per contact surface, the plane residual, the planes carrying load and those
// that switched since the last reply (which surface holds a step back). One wall: surface 0 only;
// its four points all loaded once the wall presses, none switching within a step after that.
TEST(CouplingLoop, RobinDebugLogSplitsTheResidualBySurface) {
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.kw = {0.05, 0.1, 0.2, 0.4};
  beam.kb = 0.1;
  std::vector<coupler::StepReport> reports;
  const std::string out = robin_debug_log(beam, wall, 4, true, reports);
  EXPECT_NE(out.find("robin: surface 0: plane residual "), std::string::npos) << out;
  EXPECT_NE(out.find(", 4 planes loaded, 0 switched since the last reply"), std::string::npos) << out;
  EXPECT_EQ(out.find("robin: surface 1:"), std::string::npos) << out;
}

// The switch count compares with the reply before, also across steps: a wall that reaches the four
// points only in the second step (s = 1 + 0.2 t against x0 + R = 1.05: free at t = 0.2, pressed at
// t = 0.4) gives, in that step's first iteration, four planes loaded that were all free in the
// first step's one (converged) reply.
TEST(CouplingLoop, RobinDebugLogCountsPlanesThatStartToCarryLoad) {
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.s_max = 1.2;
  std::vector<coupler::StepReport> reports;
  const std::string out = robin_debug_log(beam, wall, 5, false, reports);
  ASSERT_GE(reports.size(), 2u);
  EXPECT_EQ(reports[0].iterations, 1);  // no contact at t = 0.2: converged at once
  const auto second = out.find("step 2 iteration 0");
  ASSERT_NE(second, std::string::npos) << out;
  EXPECT_EQ(out.substr(0, second).find("robin: surface"), std::string::npos) << out;  // no iterate in step 1
  const auto line = out.find("robin: surface 0:", second);
  ASSERT_NE(line, std::string::npos) << out;
  EXPECT_NE(out.substr(line, out.find('\n', line) - line).find(", 4 planes loaded, 4 switched since the last reply"),
            std::string::npos)
      << out;
}

TEST(CouplingLoop, RobinSchemeNeedsABeamThatTakesPlanes) {
  // A beam participant without robin support fails its solve with a message saying so, and the
  // run ends with that message instead of hanging or silently running Dirichlet–Neumann.
  struct PlainBeam : test::SpringBeam {
    participant::SolveStats solve_with_planes(const std::vector<participant::Vec3>& c,
                                              const participant::ContactPlanes& p) override {
      return participant::BeamParticipant::solve_with_planes(c, p);
    }
  } beam;
  test::WallSolid wall;
  coupler::CouplingSettings s;
  s.scheme = "robin";
  coupler::Aitken aitken(0.5, 1.0);
  auto t = ramp(2);
  t.min_step = 0.4;
  try {
    coupler::run_coupled(beam, wall, t, s, aitken);
    FAIL() << "expected StepFailure";
  } catch (const StepFailure& e) {
    EXPECT_NE(std::string(e.what()).find("robin"), std::string::npos) << e.what();
  }
}

namespace {
// An acceleration whose model turns bad after three updates of a step (as IQN-ILS does with
// columns from another contact state): relaxes with ω = 0.5 at first, then steps against the
// residual. The k it is given must restart from 0 when the loop restarts it.
class SpoilingAcceleration : public coupler::Acceleration {
 public:
  void begin_step() override {
    calls_ = 0;
    ++begins;
  }
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) override {
    EXPECT_EQ(k, calls_) << "iteration index since the (re)start";
    return q + (calls_++ < 3 ? 0.5 : -0.5) * r;
  }
  void end_step(bool) override {}
  double last_factor() const override { return 0.5; }
  std::string name() const override { return "spoiling"; }
  int begins = 0;

 private:
  int calls_ = 0;
};
}  // namespace

// Consistency: with eps/kb = 0.5 the relaxed map contracts by 0.25 per good update and grows by
// 1.75 per bad one. Without a restart the bad model keeps the residual growing and the step cannot
// converge (cut to the minimum step, StepFailure); with restart_growth = 2 the loop drops the model
// when the residual doubles, and every restart gains 0.25³ x 1.75² ≈ 0.05, so it reaches the
// analytic fixed point.
TEST(CouplingLoop, ResidualGrowthRestartsTheAcceleration) {
  coupler::CouplingSettings s;
  s.rel_tol = 1e-10;
  s.abs_tol = 1e-12;
  s.max_iterations = 60;
  {
    test::SpringBeam beam;
    test::WallSolid wall;
    wall.eps = 0.5;
    SpoilingAcceleration acc;
    auto t = ramp(1);
    t.min_step = 0.5;
    EXPECT_THROW(coupler::run_coupled(beam, wall, t, s, acc), StepFailure);
  }
  test::SpringBeam beam;
  test::WallSolid wall;
  wall.eps = 0.5;
  s.restart_growth = 2.0;
  SpoilingAcceleration acc;
  const auto reports = run_ramp(beam, wall, 1, s, acc);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_GT(reports[0].restarts, 0);
  EXPECT_EQ(acc.begins, 1 + reports[0].restarts);
  EXPECT_NEAR(beam.x_committed[0], 1.0 + analytic_q(beam, wall) / beam.kb, 1e-8);
}

// Inexact solid solves (coupling.inexact_solid = eta), consistency of the bookkeeping: the solid is
// asked for the absolute tolerance eta·|w r| of the coupling residual before it (weights w = 0.1
// per point here, so |w r| = 0.1·||r||), iteration 0 of a step for eta times the previous accepted
// step's first residual, and the very first solve for its own tolerance (0). Off (eta = 0): always 0.
TEST(CouplingLoop, InexactSolidToleranceFollowsTheCouplingResidual) {
  for (const double eta : {0.0, 0.1}) {
    test::SpringBeam beam;
    test::WallSolid wall;
    coupler::CouplingSettings s;
    s.rel_tol = 1e-8;
    s.abs_tol = 1e-12;
    s.inexact_solid = eta;
    coupler::Aitken aitken(0.5, 1.0);
    const auto reports = run_ramp(beam, wall, 3, s, aitken);
    ASSERT_EQ(reports.size(), 3u);
    std::size_t solve = 0;
    double previous_first = 0.0;
    for (const auto& rep : reports) {
      for (std::size_t k = 0; k < rep.residuals.size(); ++k, ++solve) {
        ASSERT_LT(solve, wall.tolerances.size());
        const double expected = eta * 0.1 * (k == 0 ? previous_first : rep.residuals[k - 1]);
        EXPECT_NEAR(wall.tolerances[solve], expected, 1e-14 + 1e-12 * expected)
            << "step " << rep.step << " iteration " << k;
      }
      previous_first = rep.residuals[0];
    }
    EXPECT_EQ(solve, wall.tolerances.size());
    EXPECT_GT(solve, reports.size());  // some step iterates, so some tolerance follows a residual
    if (eta > 0) {
      EXPECT_GT(wall.tolerances.back(), 0.0);
    }
  }
}

// The stall guard (coupling.stall_iterations), consistency of the loop's bookkeeping on the relaxed
// map of the wall (eps/kb = 10): constant relaxation omega contracts the residual by 1 − 11 omega per
// iteration. At 0.95 (halving every 13.5 iterations) the step cannot reach its tolerance; with the
// guard at 10 every attempt ends after 11 solves (the residual of iteration 0 not halved by
// iteration 10) instead of max_iterations, and the failure says so; without the guard it uses all 50.
// At 0.8 (halving every 3.1 iterations) the step converges, and the guard changes nothing.
namespace {
coupler::CouplingSettings stall_settings(double rel_tol, int guard) {
  coupler::CouplingSettings s;
  s.rel_tol = rel_tol;
  s.abs_tol = 0.0;
  s.max_iterations = 50;
  s.stall_iterations = guard;
  return s;
}
}  // namespace

TEST(CouplingLoop, StallGuardEndsOnlyAStepThatDoesNotHalveItsResidual) {
  auto t = ramp(1);
  t.min_step = 0.5;  // one cut
  for (const int guard : {0, 10}) {
    test::SpringBeam beam;
    test::WallSolid wall;
    coupler::ConstantRelaxation slow(0.05 / 11.0);
    std::string what;
    try {
      coupler::run_coupled(beam, wall, t, stall_settings(1e-8, guard), slow);
    } catch (const StepFailure& e) {
      what = e.what();
    }
    EXPECT_NE(what.find(guard ? "coupling stalled" : "did not converge in 50"), std::string::npos) << what;
    EXPECT_EQ(wall.tolerances.size(), guard ? 2u * 11u : 2u * 50u);  // two attempts
  }
  std::vector<double> x;
  std::vector<int> iterations;
  for (const int guard : {0, 10}) {
    test::SpringBeam beam;
    test::WallSolid wall;
    coupler::ConstantRelaxation steady(0.2 / 11.0);
    const auto reports = run_ramp(beam, wall, 1, stall_settings(1e-3, guard), steady);
    ASSERT_EQ(reports.size(), 1u);
    EXPECT_TRUE(reports[0].converged);
    EXPECT_GT(reports[0].iterations, 20);  // long enough for the guard to have had its chance
    iterations.push_back(reports[0].iterations);
    x.push_back(beam.x_committed[0]);
  }
  EXPECT_EQ(iterations[0], iterations[1]);
  EXPECT_EQ(x[0], x[1]);
}

// With coupling.strict false a stalled step is accepted as one at max_iterations is: with a warning,
// not converged, after stall_iterations + 1 iterations.
TEST(CouplingLoop, StalledStepIsAcceptedWhenNotStrict) {
  test::SpringBeam beam;
  test::WallSolid wall;
  auto s = stall_settings(1e-8, 10);
  s.strict = false;
  coupler::ConstantRelaxation slow(0.05 / 11.0);
  const auto reports = run_ramp(beam, wall, 1, s, slow);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_FALSE(reports[0].converged);
  EXPECT_EQ(reports[0].iterations, 11);
}
