// The interface Newton–Krylov (newton_krylov.hpp) and the robin scheme's derivative of its map
// (robin.hpp, map_derivative), with in-process participants.
#include <gtest/gtest.h>

#include "angio/coupler/newton_krylov.hpp"
#include "angio/coupler/robin.hpp"
#include "linear_map.hpp"
#include "spring_participants.hpp"

using namespace angio;

// Analytic property: on an affine map q -> A q + b with its exact products A v, Newton's step is
// exact, and GMRES with as many products as unknowns finds it: one update reaches the fixed point,
// although the plain iteration diverges (eigenvalues −6 … 4).
TEST(NewtonKrylov, AnAffineMapsFixedPointInOneUpdate) {
  const coupler::testing::LinearMap m;
  Eigen::VectorXd b(6);
  b << 1.0, -2.0, 0.5, 3.0, -1.0, 2.0;
  coupler::NewtonKrylov nk({6, 1e-12});
  nk.set_jacobian([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return m.A * v; });
  nk.begin_step();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(6);
  const Eigen::VectorXd q1 = nk.update(q0, m.A * q0 + b - q0, 0);
  EXPECT_LT((q1 - m.fixed_point(b)).norm(), 1e-9 * m.fixed_point(b).norm());
  EXPECT_LE(nk.last_products(), 6);
  // with fewer products GMRES stops short: not the fixed point
  coupler::NewtonKrylov short_nk({2, 1e-12});
  short_nk.set_jacobian([&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return m.A * v; });
  EXPECT_GT((short_nk.update(q0, b, 0) - m.fixed_point(b)).norm(), 1e-3);
}

// A participant that cannot linearize (an empty product): the plain fixed-point update q + r.
TEST(NewtonKrylov, FailedProductGivesThePlainUpdate) {
  coupler::NewtonKrylov nk({10, 0.1});
  nk.set_jacobian([](const Eigen::VectorXd&) { return Eigen::VectorXd(); });
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(3, 1.0), r = Eigen::VectorXd::Constant(3, 0.25);
  EXPECT_EQ(nk.update(q, r, 0), q + r);
}

namespace {
// A beam whose linearized response moves point i along +x by a·shift_i + a2·turn_i·y (one plane
// per point).
struct LinearBeam : test::SpringBeam {
  explicit LinearBeam(int points, double a, double a2) : test::SpringBeam(points), a(a), a2(a2) {}
  double a, a2;
  participant::SolveStats solve_with_planes(const std::vector<participant::Vec3>&,
                                            const participant::ContactPlanes&) override {
    participant::SolveStats st;
    st.converged = true;
    return st;
  }
  participant::SolveStats linear_response(const std::vector<double>& shift, const std::vector<participant::Vec3>& turn,
                                          std::vector<participant::Vec3>& dx) override {
    dx.assign(shift.size(), {0.0, 0.0, 0.0});
    for (std::size_t i = 0; i < shift.size(); ++i) dx[i][0] = a * shift[i] + (turn.empty() ? 0.0 : a2 * turn[i][1]);
    participant::SolveStats st;
    st.converged = true;
    return st;
  }
};
// A solid whose plane j moves along its normal by b·dx_j·x and whose normal turns by c·dx_j·x along y.
struct LinearSolid : participant::SolidParticipant {
  double b, c;
  LinearSolid(double b, double c) : b(b), c(c) {}
  void begin_step(int, double) override {}
  participant::SolveStats solve(const participant::SamplePoints&, participant::ContactReply&, double) override {
    return {};
  }
  participant::SolveStats linear_response(const std::vector<participant::Vec3>& dx, std::vector<double>& shift,
                                          std::vector<participant::Vec3>& turn) override {
    shift.clear();
    turn.clear();
    for (const auto& d : dx) {
      shift.push_back(b * d[0]);
      turn.push_back({0.0, c * d[0], 0.0});
    }
    participant::SolveStats st;
    st.converged = true;
    return st;
  }
  void end_step(bool) override {}
  void finish() override {}
};
}  // namespace

// Consistency of the composition: with plain planes (normals +x) the map's derivative along v is
// b·a·(n·v) n per plane, the chain of the two participants' responses; planes without a plane in the
// reply get none. With the normals as unknowns (v twice as long: points, then normals) a turn of
// the normals (its part across them) moves the points too, and the solid's turn of its normals is
// the normals' part of the derivative. The scheme differences the planes made of the participants' responses over 1e-6
// of the largest one (here 1.2 mm of a point's move) at positions of about 1 mm: round-off of
// 2e-16 / 1e-6 relative to the largest response, up to 1e-8 of the smallest (0.024): bound 1e-7.
TEST(NewtonKrylov, RobinMapDerivativeChainsTheParticipantsResponses) {
  const int n = 5;
  LinearBeam beam(n, 0.8, 0.5);
  LinearSolid solid(-0.3, 0.2);
  coupler::Robin robin(n, false);
  participant::SamplePoints x = beam.sample_points();
  participant::ContactReply reply;
  for (int i = 0; i < n; ++i) {
    reply.surface_points.push_back({x.x[i][0] - 0.1, x.x[i][1], x.x[i][2]});
    reply.normals.push_back({1.0, 0.0, 0.0});
    reply.penalty.push_back(i == 3 ? 0.0 : 10.0);  // point 3: no surface in range
    reply.line_loads.push_back({0.0, 0.0, 0.0});
  }
  // two iterations, so that the beam has solved with the solid's planes
  robin.begin_step(0.1, false);
  robin.solve_beam(beam);
  robin.force_residual(x, reply);
  coupler::NewtonKrylov unused({10, 0.1});
  robin.next_iterate(unused, 0);
  robin.solve_beam(beam);
  robin.force_residual(x, reply);
  Eigen::VectorXd v(3 * n);
  for (int k = 0; k < 3 * n; ++k) v[k] = 0.1 * (k + 1);
  const Eigen::VectorXd jv = robin.map_derivative(beam, solid, v);
  ASSERT_EQ(jv.size(), 3 * n);
  for (int i = 0; i < n; ++i) {
    const double expected = i == 3 ? 0.0 : 0.8 * -0.3 * v[3 * i];
    EXPECT_NEAR(jv[3 * i], expected, 1e-7 * std::abs(0.8 * 0.3 * v[3 * i])) << "plane " << i;
    EXPECT_EQ(jv[3 * i + 1], 0.0);
    EXPECT_EQ(jv[3 * i + 2], 0.0);
  }
  Eigen::VectorXd w(6 * n);
  for (int k = 0; k < 6 * n; ++k) w[k] = 0.05 * (k % 7) - 0.1;
  const Eigen::VectorXd jw = robin.map_derivative(beam, solid, w);
  ASSERT_EQ(jw.size(), 6 * n);
  for (int i = 0; i < n; ++i) {
    const double move = i == 3 ? 0.0 : 0.8 * w[3 * i] + 0.5 * w[3 * n + 3 * i + 1];  // dx of point i along x
    EXPECT_NEAR(jw[3 * i], -0.3 * move, 1e-7 * 0.3) << "plane " << i;
    EXPECT_NEAR(jw[3 * n + 3 * i + 1], 0.2 * move, 1e-7 * 0.2) << "normal " << i;
    EXPECT_NEAR(jw[3 * n + 3 * i], 0.0, 1e-7 * 0.2) << "normal " << i;  // the turn is across the normal
  }
}
