// Supports and loads: prescribed displacements and rotations with load curves, uniform line
// loads, radial fixation — each against closed-form solutions.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/beam/model.hpp"

using namespace angio::beam;

namespace {
BeamModel straight_beam(int ne, double L, double E, double R) {
  BeamModel m;
  const int sec = m.add_section(circular_section(E, 0.3, R));
  for (int i = 0; i <= ne; ++i) m.add_node(Vec3(L * i / ne, 0, 0));
  for (int i = 0; i < ne; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  return m;
}

// Max column error of the assembled tangent K against central differences of the residual,
// relative to ||K||, at the model's current state (n elements on a chain of n + 1 nodes).
double tangent_fd_error(BeamModel& m, const SpMat& K, int n) {
  const Eigen::MatrixXd Kd = K;
  std::vector<Vec3> x0;
  std::vector<Quat> R0;
  for (int i = 0; i <= n; ++i) {
    x0.push_back(m.position(i));
    R0.push_back(m.rotation(i));
  }
  const double h = 1e-7;
  double err = 0;
  for (int j = 0; j < m.num_free_dofs(); ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(m.num_free_dofs());
    e(j) = h;
    Eigen::VectorXd rp, rm;
    m.set_state(x0, R0);
    m.apply_increment(e);
    m.assemble(nullptr, rp);
    m.set_state(x0, R0);
    m.apply_increment(-e);
    m.assemble(nullptr, rm);
    err = std::max(err, ((rp - rm) / (2 * h) - Kd.col(j)).norm() / Kd.norm());
  }
  return err;
}
// A straight strut of n elements along x (0.5 mm each, R = 0.06 mm), clamped at node 0, at t = 1.
void clamped_strut(BeamModel& m, int n) {
  const int sec = m.add_section(circular_section(380000.0, 0.3, 0.06));
  for (int i = 0; i <= n; ++i) m.add_node(Vec3(0.5 * i, 0.0, 0.0));
  for (int i = 0; i < n; ++i) m.add_element(i, i + 1, sec, Vec3::UnitY());
  m.fix(0, {true, true, true, true, true, true});
  m.finalize();
  m.set_time(1.0);
}

}  // namespace

// Prescribed end rotation 2π about z (rotation vector with a load curve, 20 steps) on a
// cantilever: pure bending into a full circle, tip back at the root (analytic roll-up).
TEST(BeamSupports, PrescribedRotationRollUp) {
  BeamModel m = straight_beam(16, 8.0, 1.0e4, 0.1);
  m.fix(0, {true, true, true, true, true, true});
  m.fix(16, {false, false, false, true, true, true});
  m.prescribed_rotations.push_back({16, Vec3(0, 0, 2 * M_PI), [](double t) { return t; }});
  m.newton.residual_tol = 1e-10;
  m.finalize();
  for (int s = 1; s <= 20; ++s) {
    m.set_time(s / 20.0);
    const auto st = m.solve();
    ASSERT_TRUE(st.converged) << "step " << s << ": " << st.message;
    m.commit();
  }
  EXPECT_LT(m.position(16).norm(), 1e-8);
}

// Prescribed axial displacement u at the free end: axial force EA·u/L in every element
// (bar in tension, small strain, exact for the element since Γ1 = u/L).
TEST(BeamSupports, PrescribedDisplacementAxialForce) {
  BeamModel m = straight_beam(4, 2.0, 1.0e4, 0.1);
  m.fix(0, {true, true, true, true, true, true});
  m.fix(4, {true, false, false, false, false, false});
  m.prescribed_displacements.push_back({4, 0, 0.002, [](double t) { return t; }});
  m.finalize();
  m.set_time(1.0);
  ASSERT_TRUE(m.solve().converged);
  const double EA = 1.0e4 * M_PI * 0.01;
  for (int e = 0; e < 4; ++e) EXPECT_NEAR(m.stress_resultants(e)(0), EA * 0.002 / 2.0, 1e-9);
  EXPECT_NEAR(m.position(4).x(), 2.002, 1e-12);
}

// Uniform line load q on a cantilever (small deflection): tip deflection qL⁴/(8EI)
// (Euler–Bernoulli) + qL²/(2 κGA) (shear), within 1 % with 16 elements.
TEST(BeamSupports, UniformLineLoadCantilever) {
  const double L = 10.0, E = 1.0e5, R = 0.2, q = 1e-5;
  BeamModel m = straight_beam(16, L, E, R);
  m.fix(0, {true, true, true, true, true, true});
  m.line_loads.push_back({{}, Vec3(0, 0, -q), constant_curve()});
  m.newton.residual_tol = 1e-11;
  m.finalize();
  m.set_time(1.0);
  ASSERT_TRUE(m.solve().converged);
  const Section& s = m.element_section(0);
  const double w = q * std::pow(L, 4) / (8 * s.EI2) + q * L * L / (2 * s.GA3);
  EXPECT_NEAR(-m.position(16).z(), w, 0.01 * w);
}

// Radial-only fixation: the node moves along its initial radial line w.r.t. the axis.
TEST(BeamSupports, RadialFixationKeepsNodeOnRadialLine) {
  BeamModel m;
  const int sec = m.add_section(circular_section(1.0e4, 0.3, 0.05));
  const int a = m.add_node(Vec3(1, 0, 0));
  const int b = m.add_node(Vec3(1, 1, 0.5));
  m.add_element(a, b, sec);
  m.axis.points = {Vec3(0, 0, -1), Vec3(0, 0, 1)};
  m.fix_radial_only(a);
  m.fix(a, {false, false, false, true, true, true});
  m.fix(b, {true, true, true, false, false, false});
  m.prescribed_displacements.push_back({b, 0, 0.05, constant_curve()});
  m.finalize();
  m.set_time(1.0);
  ASSERT_TRUE(m.solve().converged);
  EXPECT_NEAR(m.position(a).y(), 0.0, 1e-12);
  EXPECT_NEAR(m.position(a).z(), 0.0, 1e-12);
  EXPECT_GT(std::abs(m.position(a).x() - 1.0), 1e-6);  // it did move radially
}

// Assembled tangent (incl. the load stiffness of a follower radial line load and a plastic
// state) vs central finite differences of the assembled residual w.r.t. the multiplicative
// increments of all free DOFs, at a deformed state of a small generated-like arc of beams.
TEST(BeamSupports, AssembledTangentWithFollowerLoadMatchesFiniteDifferences) {
  BeamModel m;
  Section s = circular_section(380000.0, 0.3, 0.06);
  add_bending_plasticity(s, 380000.0, 0.08, 64000.0);
  const int sec = m.add_section(s);
  const int n = 6;
  for (int i = 0; i <= n; ++i) {
    const double a = 0.8 * i / n;
    m.add_node(Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), 0.1 * i));
  }
  for (int i = 0; i < n; ++i) m.add_element(i, i + 1, sec);
  m.axis.points = {Vec3(0, 0, -1), Vec3(0, 0, 1)};
  m.fix(0, {true, true, true, true, true, true});
  m.radial_loads.push_back({{}, 0.3, constant_curve(), true});
  m.line_loads.push_back({{}, Vec3(0.01, -0.02, 0.03), constant_curve()});
  m.finalize();
  m.set_time(1.0);
  // move to a deformed, partly plastic state
  Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(m.num_free_dofs(), -0.02, 0.03);
  m.apply_increment(d);
  SpMat K;
  Eigen::VectorXd r;
  m.assemble(&K, r);
  bool any_plastic = false;
  for (int e = 0; e < n; ++e) any_plastic |= m.trial_state(e).kappa_bar > 0;
  EXPECT_TRUE(any_plastic);
  const double err = tangent_fd_error(m, K, n);
  std::printf("assembled tangent FD error %.2e\n", err);
  EXPECT_LT(err, 2e-9);  // a sign error in the load stiffness gives 2e-7
}

// Robin coupling mode: frozen contact planes at the sample points (plane_penalty.hpp) add their
// penalty load and its stiffness; the assembled tangent must match finite differences with some
// sample points pressed into their plane and others free (both branches of ⟨g⟩), for the linear
// law and the linear-quadratic one (g0 > 0, points inside its quadratic zone).
TEST(BeamSupports, AssembledTangentWithContactPlanesMatchesFiniteDifferences) {
  BeamModel m;
  const int n = 4;
  clamped_strut(m, n);
  std::vector<BeamModel::SamplePlane> planes(m.num_sample_points());
  int active = 0;
  for (int g = 0; g < m.num_sample_points(); ++g) {
    // a tilted plane below the beam; every other point is pushed 0.02 mm into it
    planes[g].n = Vec3(0.2, 1.0, 0.3).normalized();
    planes[g].s = m.sample_position(g) - (0.06 + (g % 2 ? 0.02 : -0.01)) * planes[g].n;
    planes[g].eps = 10.0;
    planes[g].g0 = g < 12 ? 0.0 : 0.015;  // linear law, and the linear-quadratic law whose
    active += g % 2;                      // quadratic zone holds the points 0.01 mm off
  }
  m.set_sample_planes(planes);
  Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(m.num_free_dofs(), -1e-4, 2e-4);
  m.apply_increment(d);
  SpMat K;
  Eigen::VectorXd r;
  m.assemble(&K, r);
  ASSERT_GT(active, 0);
  const double err = tangent_fd_error(m, K, n);
  std::printf("assembled tangent FD error with planes %.2e\n", err);
  EXPECT_LT(err, 2e-9);
  // The planes load the beam: the residual differs from the plane-free one by −Σ w N q.
  Eigen::VectorXd r_free;
  m.set_sample_planes({});
  m.assemble(nullptr, r_free);
  EXPECT_GT((r - r_free).norm(), 1e-4);
}

// Robin mode with two planes per sample point (a strut pressed between balloon and artery): the
// loads add up (sample_contact_loads = Σ of the two plane laws, exact) and the assembled tangent
// with both planes active matches finite differences.
TEST(BeamSupports, TwoContactPlanesPerPointAddUpAndLinearize) {
  BeamModel m;
  const int n = 4;
  clamped_strut(m, n);
  const int ng = m.num_sample_points();
  std::vector<BeamModel::SamplePlane> planes(2 * ng);
  const Vec3 nb = Vec3(0.2, 1.0, 0.3).normalized();
  for (int g = 0; g < ng; ++g) {
    BeamModel::SamplePlane& below = planes[2 * g];  // pushes up (+nb), 0.02 mm penetration
    below.n = nb;
    below.s = m.sample_position(g) - (0.06 - 0.02) * nb;
    below.eps = 10.0;
    BeamModel::SamplePlane& above = planes[2 * g + 1];  // pushes down, 0.01 mm on every other point
    above.n = -nb;
    above.s = m.sample_position(g) + (0.06 - (g % 2 ? 0.01 : -0.01)) * nb;
    above.eps = 30.0;
  }
  m.set_sample_planes(planes);
  const auto q = m.sample_contact_loads();
  for (int g = 0; g < ng; ++g) {
    const Vec3 expected = 10.0 * 0.02 * nb - 30.0 * (g % 2 ? 0.01 : 0.0) * nb;
    EXPECT_LT((q[g] - expected).norm(), 1e-12) << "point " << g;
  }
  Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(m.num_free_dofs(), -1e-4, 2e-4);
  m.apply_increment(d);
  SpMat K;
  Eigen::VectorXd r;
  m.assemble(&K, r);
  const double err = tangent_fd_error(m, K, n);
  EXPECT_LT(err, 2e-9);
  // a number of planes that is not a multiple of the points is refused
  planes.pop_back();
  EXPECT_THROW(m.set_sample_planes(planes), std::invalid_argument);
}

// plane_response at the state (x, R) of converged planes `planes`, for the given shift and turn.
std::vector<Vec3> m_response_with_turn(BeamModel& m, const std::vector<BeamModel::SamplePlane>& planes,
                                       const std::vector<Vec3>& x, const std::vector<Quat>& R,
                                       const std::vector<double>& shift, const std::vector<Vec3>& turn) {
  m.set_sample_planes(planes);
  m.set_state(x, R);
  return m.plane_response(shift, turn);
}

// The interface Newton–Krylov's beam response (BeamModel::plane_response): the sample points'
// displacement per unit shift of the planes along their normals, from the tangent at a converged
// state, against central differences of converged Newton solves with the planes shifted by ±h
// (consistency of the linearization). A line load presses every point into its tilted plane
// (penetrations of about 0.05 mm: no point near the law's switch), so the response is smooth.
TEST(BeamSupports, PlaneResponseMatchesDifferencesOfSolves) {
  BeamModel m;
  const int n = 4;
  clamped_strut(m, n);
  m.line_loads.push_back({{}, Vec3(0.0, -0.5, 0.0)});
  m.newton.residual_tol = 1e-12;
  m.newton.residual_rel_tol = 0.0;
  const int ng = m.num_sample_points();
  const Vec3 nb = Vec3(0.2, 1.0, 0.3).normalized();
  std::vector<BeamModel::SamplePlane> planes(ng);
  for (int g = 0; g < ng; ++g) {
    planes[g].n = nb;
    planes[g].s = m.sample_position(g) - 0.06 * nb;
    planes[g].eps = 10.0;
  }
  m.set_sample_planes(planes);
  ASSERT_TRUE(m.solve().converged);
  std::vector<double> shift(ng);
  for (int g = 0; g < ng; ++g) shift[g] = 1.0 + 0.5 * std::sin(0.7 * g);  // a smooth, non-uniform push
  const std::vector<Vec3> dx = m.plane_response(shift);
  const std::vector<Vec3> x0 = m.positions();
  std::vector<Quat> R0;
  for (int i = 0; i < m.num_nodes(); ++i) R0.push_back(m.rotation(i));
  // the points solved with the planes shifted by a·shift and their normals turned by a·turn
  auto solved_points = [&](double a, const std::vector<Vec3>& turn) {
    std::vector<BeamModel::SamplePlane> p = planes;
    for (int g = 0; g < ng; ++g) {
      p[g].s += a * shift[g] * nb;
      if (!turn.empty()) p[g].n = (nb + a * turn[g]).normalized();
    }
    m.set_sample_planes(p);
    m.set_state(x0, R0);
    EXPECT_TRUE(m.solve().converged);
    std::vector<Vec3> x(ng);
    for (int g = 0; g < ng; ++g) x[g] = m.sample_position(g);
    return x;
  };
  const double h = 1e-5;  // mm: truncation O(h²) against Newton's residual 1e-12 N / h
  const std::vector<Vec3> xp = solved_points(h, {}), xm = solved_points(-h, {});
  double err = 0.0, size = 0.0;
  for (int g = 0; g < ng; ++g) {
    const Vec3 fd = (xp[g] - xm[g]) / (2.0 * h);
    err = std::max(err, (fd - dx[g]).norm());
    size = std::max(size, fd.norm());
  }
  std::printf("plane response %.3e, difference to the solves %.2e\n", size, err);
  ASSERT_GT(size, 0.1);  // the points follow their planes
  EXPECT_LT(err, 1e-6 * size);
  // the planes' normals turned as well (across them): the forces' direction changes and the strut
  // slides; forward differences in the beam (O(h) in the turn), so 1e-5 of the response
  std::vector<Vec3> turn(ng);
  for (int g = 0; g < ng; ++g) {
    const Vec3 t(0.3 * std::cos(0.5 * g), 0.2, -0.4);
    turn[g] = t - t.dot(nb) * nb;
  }
  const std::vector<Vec3> dxt = m_response_with_turn(m, planes, x0, R0, shift, turn);
  const std::vector<Vec3> tp = solved_points(h, turn), tm = solved_points(-h, turn);
  double err_t = 0.0, size_t_ = 0.0, turned = 0.0;
  for (int g = 0; g < ng; ++g) {
    const Vec3 fd = (tp[g] - tm[g]) / (2.0 * h);
    err_t = std::max(err_t, (fd - dxt[g]).norm());
    size_t_ = std::max(size_t_, fd.norm());
    turned = std::max(turned, (dxt[g] - dx[g]).norm());
  }
  std::printf("with turned normals %.3e (the turn's part %.3e), difference to the solves %.2e\n", size_t_, turned,
              err_t);
  ASSERT_GT(turned, 0.01);  // the turn moves the points
  EXPECT_LT(err_t, 1e-5 * size_t_);
}
