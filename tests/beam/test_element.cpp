// Element-level tests: tangent vs. central finite differences (elastic and plastic) and
// objectivity under a superposed rigid motion.
#include <gtest/gtest.h>

#include "angio/beam/element.hpp"

using namespace angio::beam;

namespace {

struct Config {
  Vec3 x1, x2;
  Quat R1, R2;
};

Vec12 residual_at(const Section& s, const ElementReference& ref, const Config& c, const PlasticState& st,
                  const Vec12& d) {
  const Vec3 x1 = c.x1 + d.segment<3>(0), x2 = c.x2 + d.segment<3>(6);
  const Quat R1 = quat_exp(d.segment<3>(3)) * c.R1, R2 = quat_exp(d.segment<3>(9)) * c.R2;
  return evaluate_element(s, ref, x1, x2, R1, R2, st, false).residual;
}

double fd_error(const Section& s, const ElementReference& ref, const Config& c, const PlasticState& st) {
  const ElementResult ev = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, st, true);
  Mat12 Kfd;
  const double h = 1e-6;
  for (int i = 0; i < 12; ++i) {
    Vec12 d = Vec12::Zero();
    d(i) = h;
    Kfd.col(i) = (residual_at(s, ref, c, st, d) - residual_at(s, ref, c, st, -d)) / (2 * h);
  }
  return (Kfd - ev.tangent).norm() / ev.tangent.norm();
}

Config deformed(const ElementReference&) {
  Config c;
  c.x1 = Vec3(0.01, -0.02, 0.03);
  c.x2 = Vec3(0.9, 0.35, -0.2);
  c.R1 = quat_exp(Vec3(0.3, -0.5, 0.2));
  c.R2 = quat_exp(Vec3(-0.4, 0.7, 0.9));
  return c;
}

}  // namespace

// Compares the AD tangent with central finite differences of the residual w.r.t. the
// multiplicative rotation increments (elastic material).
TEST(BeamElement, TangentMatchesFiniteDifferencesElastic) {
  Section s = circular_section(1000.0, 0.3, 0.1);
  const ElementReference ref =
      make_element_reference(Vec3::Zero(), Vec3(1, 0.2, 0.1), triad_from_tangent(Vec3(1, 0.2, 0.1), Vec3::UnitZ()),
                             triad_from_tangent(Vec3(1, 0.25, 0.05), Vec3::UnitZ()));
  EXPECT_LT(fd_error(s, ref, deformed(ref), PlasticState{}), 1e-6);
}

// Same comparison in the plastic regime (radial return active, consistent tangent).
TEST(BeamElement, TangentMatchesFiniteDifferencesPlastic) {
  Section s = circular_section(380000.0, 0.3, 0.06);
  add_bending_plasticity(s, 380000.0, 0.08, 64000.0);
  const Vec3 t(1, 0, 0);
  const ElementReference ref = make_element_reference(Vec3::Zero(), t, triad_from_tangent(t, Vec3::UnitZ()),
                                                      triad_from_tangent(t, Vec3::UnitZ()));
  Config c;
  c.x1 = Vec3::Zero();
  c.x2 = Vec3(0.99, 0.05, 0.01);
  c.R1 = quat_exp(Vec3(0.01, 0.05, -0.06));
  c.R2 = quat_exp(Vec3(-0.02, -0.04, 0.08));
  PlasticState st;
  st.omega_pl = Vec3(0, 0.01, -0.02);
  st.kappa_bar = 0.03;
  const ElementResult ev = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, st, true);
  ASSERT_TRUE(ev.section.yielding);
  EXPECT_LT(fd_error(s, ref, c, st), 1e-5);
}

// A superposed rigid rotation Q and translation c leaves strains and convected stress
// resultants unchanged (objectivity), and rotates the internal force vector by Q.
TEST(BeamElement, Objectivity) {
  Section s = circular_section(1000.0, 0.3, 0.1);
  const Vec3 t(1, 0.2, 0.1);
  const ElementReference ref = make_element_reference(Vec3::Zero(), t, triad_from_tangent(t, Vec3::UnitZ()),
                                                      triad_from_tangent(t, Vec3::UnitY()));
  Config c = deformed(ref);
  const Quat Q = quat_exp(Vec3(1.1, -2.0, 0.7));
  const Vec3 tr(3, -1, 2);
  const auto a = evaluate_element(s, ref, c.x1, c.x2, c.R1, c.R2, {}, false);
  const auto b = evaluate_element(s, ref, Q * c.x1 + tr, Q * c.x2 + tr, Q * c.R1, Q * c.R2, {}, false);
  EXPECT_LT((a.strain - b.strain).norm(), 1e-12);
  EXPECT_LT((a.section.stress - b.section.stress).norm(), 1e-9 * a.section.stress.norm());
  for (int k = 0; k < 4; ++k)
    EXPECT_LT((Q * Vec3(a.residual.segment<3>(3 * k)) - b.residual.segment<3>(3 * k)).norm(), 1e-9 * a.residual.norm());
  // reference configuration is stress free
  const auto z = evaluate_element(s, ref, Vec3::Zero(), t, Quat::Identity(), Quat::Identity(), {}, false);
  EXPECT_LT(z.residual.norm(), 1e-12);
}
