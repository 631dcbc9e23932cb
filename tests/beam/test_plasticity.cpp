// Elasto-plastic bending (paper Appendix C): return mapping kernel and a single element in pure
// bending loaded past yield and unloaded, compared with the analytic moment–curvature path.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/beam/model.hpp"

using namespace angio::beam;

namespace {
const double E = 380000.0, nu = 0.3, R = 0.06, My0 = 0.08, Eep = 64000.0;
Section paper_section() {
  Section s = circular_section(E, nu, R);
  add_bending_plasticity(s, E, My0, Eep);
  return s;
}
}  // namespace

// Kernel: on the yield surface after a plastic step (|M_b| = My0 + H I κ̄), the flow is along
// the elastic bending curvature, torsion stays elastic, and the algorithmic tangent equals the
// finite-difference derivative of the returned moments.
TEST(BeamPlasticity, ReturnMappingKernel) {
  const Section s = paper_section();
  const double H = Eep / (1 - Eep / E);
  const double I = M_PI * std::pow(R, 4) / 4;
  EXPECT_NEAR(s.HI, H * I, 1e-12);
  EXPECT_NEAR(s.EI2, E * I, 1e-12);
  Vec6 strain;
  strain << 1e-4, 2e-4, -1e-4, 0.05, 0.04, -0.03;
  PlasticState st0;
  const SectionResponse r = evaluate_section(s, strain, st0);
  ASSERT_TRUE(r.yielding);
  const double Mb = std::hypot(r.stress(4), r.stress(5));
  EXPECT_NEAR(Mb, My0 + s.HI * r.state.kappa_bar, 1e-12);
  EXPECT_NEAR(r.stress(3), s.GJ * strain(3), 1e-14);  // torsion elastic
  EXPECT_NEAR(r.state.omega_pl(0), 0.0, 0.0);
  // plastic flow parallel to the bending moment
  EXPECT_NEAR(r.state.omega_pl(1) * r.stress(5) - r.state.omega_pl(2) * r.stress(4), 0.0, 1e-14);
  Mat6 Cfd;
  for (int j = 0; j < 6; ++j) {
    Vec6 d = Vec6::Zero();
    d(j) = 1e-7;
    Cfd.col(j) = (evaluate_section(s, strain + d, st0).stress - evaluate_section(s, strain - d, st0).stress) / 2e-7;
  }
  EXPECT_LT((Cfd - r.tangent).norm() / r.tangent.norm(), 1e-7);
  // elastic unloading from the returned state
  const SectionResponse u = evaluate_section(s, strain * 0.9, r.state);
  EXPECT_FALSE(u.yielding);
}

// Single element, clamped at one end, pure end moment about e3 ramped to 2.5 My0 and back to 0.
// Analytic (Appendix C, linear isotropic hardening, monotonic loading then elastic unloading):
//   loading: κ = M/EI (M ≤ My0), κ = M/EI + (M − My0)/(H I) beyond yield;
//   unloading: κ = κ_p + M/EI with residual curvature κ_p = (M_max − My0)/(H I).
TEST(BeamPlasticity, SingleElementMomentCurvaturePath) {
  BeamModel m;
  const Section s = paper_section();
  const int sec = m.add_section(s);
  m.add_node(Vec3::Zero());
  m.add_node(Vec3(0.5, 0, 0));
  m.add_element(0, 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  const double Mmax = 2.5 * My0;
  auto curve = [](double t) { return t <= 1 ? t : 2 - t; };
  m.nodal_loads.push_back({1, Vec3::Zero(), Vec3(0, 0, Mmax), curve});
  m.newton.residual_tol = 1e-12;
  m.finalize();
  const double EI = s.EI2, HI = s.HI;
  const int steps = 20;
  double maxerr = 0;
  for (int k = 1; k <= steps; ++k) {
    const double t = 2.0 * k / steps;
    m.set_time(t);
    const NewtonStats st = m.solve();
    ASSERT_TRUE(st.converged) << st.message;
    m.commit();
    const double M = Mmax * curve(t);
    double kappa;
    if (t <= 1)
      kappa = M <= My0 ? M / EI : M / EI + (M - My0) / HI;
    else
      kappa = (Mmax - My0) / HI + M / EI;
    const double k_num = m.strain(0)(5);
    maxerr = std::max(maxerr, std::abs(k_num - kappa));
    EXPECT_NEAR(k_num, kappa, 1e-8 * std::max(1.0, std::abs(kappa))) << "t = " << t;
    EXPECT_NEAR(m.stress_resultants(0)(5), M, 1e-8);
  }
  EXPECT_NEAR(m.committed_state(0).kappa_bar, (Mmax - My0) / HI, 1e-10);
  EXPECT_NEAR(m.strain(0)(5), (Mmax - My0) / HI, 1e-10);  // residual curvature
}

// A rejected step restores the committed plastic state exactly.
TEST(BeamPlasticity, RejectRestoresCommittedState) {
  BeamModel m;
  const int sec = m.add_section(paper_section());
  m.add_node(Vec3::Zero());
  m.add_node(Vec3(0.5, 0, 0));
  m.add_element(0, 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  m.nodal_loads.push_back({1, Vec3::Zero(), Vec3(0, 0, 0.2), [](double t) { return t; }});
  m.finalize();
  m.set_time(0.5);
  ASSERT_TRUE(m.solve().converged);
  m.commit();
  const double kb = m.committed_state(0).kappa_bar;
  const Vec3 x = m.position(1);
  m.set_time(1.0);
  ASSERT_TRUE(m.solve().converged);
  EXPECT_GT(m.trial_state(0).kappa_bar, kb);
  m.restore();
  EXPECT_EQ(m.trial_state(0).kappa_bar, kb);
  EXPECT_EQ((m.position(1) - x).norm(), 0.0);
}
