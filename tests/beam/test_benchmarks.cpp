// Structural benchmarks of the Simo–Reissner model against analytic and published solutions.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/beam/model.hpp"

using namespace angio::beam;

namespace {

// Runs `steps` equal load steps (load curves scale with t in [0, 1]); returns false on failure.
bool run_steps(BeamModel& m, int steps, std::vector<NewtonStats>* stats = nullptr) {
  for (int s = 1; s <= steps; ++s) {
    m.set_time(static_cast<double>(s) / steps);
    NewtonStats st = m.solve();
    if (stats) stats->push_back(st);
    if (!st.converged) {
      ADD_FAILURE() << "step " << s << ": " << st.message;
      return false;
    }
    m.commit();
  }
  return true;
}

Curve ramp() {
  return [](double t) { return t; };
}

}  // namespace

// Cantilever roll-up: end moment M = 2πEI/L bends a straight cantilever into a full circle
// (analytic: the tip returns to the clamped end, tip rotation 2π). With the 2-node element
// and constant curvature the nodes lie exactly on a closed regular polygon.
TEST(BeamBenchmark, CantileverRollUpFullCircle) {
  BeamModel m;
  const double L = 10.0, E = 1.0e4, nu = 0.3, R = 0.1;
  const int ne = 20;
  const int sec = m.add_section(circular_section(E, nu, R));
  for (int i = 0; i <= ne; ++i) m.add_node(Vec3(L * i / ne, 0, 0));
  for (int i = 0; i < ne; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  const double EI = E * M_PI * std::pow(R, 4) / 4;
  m.nodal_loads.push_back({ne, Vec3::Zero(), Vec3(0, 0, 2 * M_PI * EI / L), ramp()});
  m.newton.residual_tol = 1e-10;
  m.finalize();
  ASSERT_TRUE(run_steps(m, 10));
  EXPECT_LT(m.position(ne).norm(), 1e-8 * L);
  // half-way node: diameter of the circle L/π (polygon circumradius differs by O(h^2))
  const double rho = L / (2 * M_PI);
  const double rho_poly = (L / ne) / (2 * std::sin(M_PI / ne));
  EXPECT_NEAR(m.position(ne / 2).norm(), 2 * rho_poly, 1e-8);
  EXPECT_NEAR(m.position(ne / 2).norm(), 2 * rho, 0.01 * 2 * rho);
}

// 45° bend (Bathe & Bolourchi 1979; Simo & Vu-Quoc 1986, Crisfield 1990): R = 100, arc in the
// x–y plane clamped at the origin with tangent +y, 8 elements, out-of-plane tip load P (z).
// EA = 1e7, GA = 5e6, EI = 1e7/12, GJ = 0.705e6 (unit square section, E = 1e7, G = 5e6).
// Published tip positions: P = 300: (22.5, 59.2, 39.5); P = 600: (15.9, 47.2, 53.4)
// (Bathe–Bolourchi; Simo–Vu-Quoc: (22.33, 58.84, 40.08) and (15.79, 47.23, 53.37)).
// Tolerance: 1.0 in each coordinate (1 % of R), the spread between published solutions.
TEST(BeamBenchmark, FortyFiveDegreeBend) {
  BeamModel m;
  Section s;
  s.EA = 1e7;
  s.GA2 = s.GA3 = 5e6;
  s.GJ = 0.705e6;
  s.EI2 = s.EI3 = 1e7 / 12.0;
  s.contact_radius = 0.5;
  const int sec = m.add_section(s);
  const int ne = 8;
  const double Rb = 100;
  for (int i = 0; i <= ne; ++i) {
    const double a = M_PI / 4 * i / ne;
    m.add_node(Vec3(Rb * (1 - std::cos(a)), Rb * std::sin(a), 0));
  }
  // nodal triads tangent to the arc, e2 toward the centre (in plane), e3 = z
  for (int i = 0; i < ne; ++i) {
    auto triad = [&](int n) {
      const double a = M_PI / 4 * n / ne;
      return triad_from_tangent(Vec3(std::sin(a), std::cos(a), 0), Vec3(std::cos(a), -std::sin(a), 0));
    };
    m.add_element(i, i + 1, sec, triad(i), triad(i + 1));
  }
  m.fix(0, {true, true, true, true, true, true});
  double P = 0;
  m.nodal_loads.push_back({ne, Vec3(0, 0, 1), Vec3::Zero(), [&P](double t) { return P * t; }});
  m.newton.residual_tol = 1e-7;
  m.newton.line_search = true;  // 3 big steps of 100: energy line search needed from the straight start
  m.finalize();
  P = 300;
  ASSERT_TRUE(run_steps(m, 3));
  const Vec3 tip300 = m.position(ne);
  std::printf("45deg bend P=300 tip: %.3f %.3f %.3f\n", tip300.x(), tip300.y(), tip300.z());
  EXPECT_NEAR(tip300.x(), 22.5, 1.0);
  EXPECT_NEAR(tip300.y(), 59.2, 1.0);
  EXPECT_NEAR(tip300.z(), 39.5, 1.0);
  // continue to P = 600: load curve value grows from 300 to 600
  for (int s2 = 1; s2 <= 3; ++s2) {
    P = 300.0 + 300.0 * s2 / 3.0;
    m.set_time(1.0);
    NewtonStats st = m.solve();
    ASSERT_TRUE(st.converged) << st.message;
    m.commit();
  }
  const Vec3 tip600 = m.position(ne);
  std::printf("45deg bend P=600 tip: %.3f %.3f %.3f\n", tip600.x(), tip600.y(), tip600.z());
  EXPECT_NEAR(tip600.x(), 15.9, 1.0);
  EXPECT_NEAR(tip600.y(), 47.2, 1.0);
  EXPECT_NEAR(tip600.z(), 53.4, 1.0);
}

// Quadratic convergence of Newton on an elastic large-rotation problem (cantilever under a
// spatially fixed end moment + transverse force, 10 load steps): the ratio r_{k+1}/r_k^2 stays
// bounded over the last iterations (asymptotic quadratic rate), checked over all load steps.
TEST(BeamBenchmark, NewtonConvergesQuadratically) {
  BeamModel m;
  const int sec = m.add_section(circular_section(1.0e4, 0.3, 0.1));
  const int ne = 10;
  for (int i = 0; i <= ne; ++i) m.add_node(Vec3(i, 0, 0));
  for (int i = 0; i < ne; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  m.nodal_loads.push_back({ne, Vec3(0, 0, 0.02), Vec3(0, 0.1, 0.15), ramp()});
  m.newton.residual_tol = 1e-11;
  m.newton.residual_rel_tol = 0;
  m.newton.increment_tol = 1e-11;
  m.finalize();
  std::vector<NewtonStats> all;
  ASSERT_TRUE(run_steps(m, 10, &all));
  // rotation magnitude reached is large
  EXPECT_GT(quat_log(m.rotation(ne)).norm(), 1.0);
  // Ratio test in the asymptotic range (residual below 1 % of the step's initial residual and
  // well above the round-off floor ~1e-12): r_{k+1} <= C r_k^2 / r_0 with C = 50.
  int checked = 0;
  for (const auto& st : all) {
    const auto& h = st.residual_history;
    for (size_t k = 1; k + 1 < h.size(); ++k) {
      if (h[k] > 1e-2 * h[0] || h[k + 1] < 1e-10) continue;
      EXPECT_LE(h[k + 1], 50.0 * h[k] * h[k] / h[0]) << "k=" << k << " " << h[k] << " -> " << h[k + 1];
      ++checked;
    }
  }
  EXPECT_GE(checked, 2);
  const auto& h = all.front().residual_history;
  std::printf("residual history:");
  for (double v : h) std::printf(" %.2e", v);
  std::printf("\n");
}

// Both sparse backends give the same solution.
TEST(BeamBenchmark, LinearSolverBackendsAgree) {
  Vec3 tips[3];
  const char* names[3] = {"umfpack", "sparselu", "klu"};
  for (int b = 0; b < 3; ++b) {
    BeamModel m;
    const int sec = m.add_section(circular_section(1.0e4, 0.3, 0.1));
    for (int i = 0; i <= 6; ++i) m.add_node(Vec3(i, 0, 0));
    for (int i = 0; i < 6; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
    m.fix(0, {true, true, true, true, true, true});
    m.nodal_loads.push_back({6, Vec3(0, 0.02, 0.03), Vec3::Zero(), ramp()});
    m.newton.linear_solver = names[b];
    m.finalize();
    ASSERT_TRUE(run_steps(m, 2));
    tips[b] = m.position(6);
  }
  EXPECT_LT((tips[0] - tips[1]).norm(), 1e-9);
  EXPECT_LT((tips[0] - tips[2]).norm(), 1e-9);
}
