// Line contact along the averaged nodal normal field (normal_field.hpp, LineContactParams::averaged_normals).
#include <algorithm>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "angio/participant/penalty_law.hpp"
#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

namespace {
// Some fixed, non-parallel unit nodal normals for one face (the kernel takes them as inputs).
FaceX tilted_normals(FaceKind k, const FaceX& X) {
  FaceX Nn(3, num_nodes(k));
  const Vec3 c = evaluate(k, X, center_xi(k)).n;
  for (int a = 0; a < Nn.cols(); ++a)
    Nn.col(a) = (c + 0.15 * Vec3(std::sin(1.0 + a), std::cos(2.0 * a), 0.3 * a - 0.4)).normalized();
  return Nn;
}

// Runs the averaged-normal kernel for a point against one face with fixed nodal normals.
struct KernelOut {
  PointContact pc;
  Eigen::VectorXd r;
  Eigen::MatrixXd K;
};
KernelOut run(FaceKind k, const FaceX& X, const FaceX& Nn, const BeamPoint& bp, const LineContactParams& par,
              bool tangent) {
  KernelOut o;
  const NormalFieldProjection p = project_along_normals(k, X, Nn, bp.x);
  EXPECT_TRUE(p.valid);
  line_point_kernel_averaged(bp, k, X, Nn, p, par, o.pc, o.r, tangent ? &o.K : nullptr);
  return o;
}

// Consistency: K = dr/d[X, Nn] and dq/dx against central finite differences (nodes and nodal normals as
// independent inputs, as the kernel documents), and Newton's third law sum_a f_a = -w q.
void check_kernel(FaceKind k, const FaceX& X, const BeamPoint& bp, double g0) {
  LineContactParams par;
  par.penalty = 10.0;
  par.regularization = g0;
  par.beam_tangent = true;
  par.averaged_normals = true;
  const FaceX Nn = tilted_normals(k, X);
  const KernelOut o = run(k, X, Nn, bp, par, true);
  ASSERT_TRUE(o.pc.active);
  const Eigen::Index nx = X.size();
  Eigen::VectorXd u(2 * nx);
  u << flatten(X), flatten(Nn);
  auto res = [&](const Eigen::VectorXd& v) {
    return run(k, unflatten(v.head(nx)), unflatten(v.tail(nx)), bp, par, false).r;
  };
  EXPECT_LT(rel_diff(o.K, fd_jacobian(res, u, 1e-6)), 1e-6) << name(k);
  auto qx = [&](const Eigen::VectorXd& v) {
    BeamPoint b = bp;
    b.x = v;
    return Eigen::VectorXd(run(k, X, Nn, b, par, false).pc.q);
  };
  EXPECT_LT(rel_diff(o.pc.dq_dx, fd_jacobian(qx, bp.x, 1e-6)), 1e-6) << name(k);
  Vec3 fsum = Vec3::Zero();
  for (int a = 0; a < num_nodes(k); ++a) fsum -= o.r.segment<3>(3 * a);
  EXPECT_LT((fsum + bp.w * o.pc.q).norm(), 1e-13 * (1 + bp.w * o.pc.q.norm()));
}

// Two flat quad strips meeting at a groove along the y axis (x = 0), faces inclined by +-angle: the surface
// z = tan(angle) |x|, normals up (+z side).
test::Mesh groove(double angle) {
  test::Mesh m = flat_quads(4, 2, 0.1, 0.1, 0.0, -0.2, 0.0);
  for (Vec3& x : m.x) x.z() = std::tan(angle) * std::abs(x.x());
  return m;
}

// A quarter cylinder (R = 0.55 mm) of quad4 or tri6 faces, every node moved by up to 0.01 mm (seeded).
test::Mesh perturbed_quarter_cylinder(FaceKind kind, unsigned seed) {
  test::Mesh m = cylinder(kind, 0.55, 0.6, 10, 3, 0.0, M_PI / 2);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  for (Vec3& x : m.x) x += 0.01 * Vec3(U(rng), U(rng), U(rng));
  return m;
}

// 12 stent points (R = 0.06 mm) along a helix at radius 0.59 mm: pressed about 0.02 mm into that cylinder.
std::vector<BeamPoint> helix_points() {
  std::vector<BeamPoint> pts;
  for (int i = 0; i < 12; ++i) pts.push_back({cyl(0.59, 0.2 + 0.1 * i, 0.1 + 0.035 * i), 0.03, 0.06});
  return pts;
}
}  // namespace

// Compares against: the closest-point projection, which on a flat surface is the same (s, d, normal +z).
TEST(NormalField, FlatSurfaceEqualsClosestPoint) {
  test::Mesh m = flat_quads(3, 3, 0.2, 0.25, 0.5);
  SurfaceSearch S(m.surface, 0.3);
  S.enable_normal_field();
  S.update(m.x);
  for (const Vec3& x : {Vec3(0.13, 0.41, 0.57), Vec3(0.2, 0.25, 0.45), Vec3(0.59, 0.7, 0.6)}) {
    const SurfaceNormalProjection a = S.along_normals(x);
    const SurfaceProjection c = S.closest(x);
    ASSERT_TRUE(a.found && c.found);
    EXPECT_NEAR(a.proj.d, c.proj.d, 1e-13);
    EXPECT_LT((a.proj.s - c.proj.s).norm(), 1e-13);
    EXPECT_LT((a.proj.nu - Vec3::UnitZ()).norm(), 1e-13);
  }
}

// Compares against: the exact projection on a cylinder of radius Rc, where the averaged nodal normals are the
// radial directions at the nodes: along a face's mid-line (nodes at equal angles from it) the field normal is
// radial, so d = |x_perp| - (chord mid-point distance).
TEST(NormalField, CylinderMidLineIsRadial) {
  const double Rc = 1.0;
  const int nt = 16;
  test::Mesh m = cylinder(FaceKind::Quad4, Rc, 1.0, nt, 4);
  SurfaceSearch S(m.surface, 0.3);
  S.enable_normal_field();
  S.update(m.x);
  const double th = 2 * M_PI / nt * 2.5;  // mid-line of face column 2
  const double r = 1.07;
  const SurfaceNormalProjection p = S.along_normals(Vec3(r * std::cos(th), r * std::sin(th), 0.3));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.proj.d, r - Rc * std::cos(M_PI / nt), 1e-12);
  EXPECT_LT((p.proj.nu - Vec3(std::cos(th), std::sin(th), 0)).norm(), 1e-12);
}

// Compares against: central finite differences of the kernel (quad4 warped, tri6 curved, tri3; with the linear
// and the linear-quadratic penalty law) and the force balance.
TEST(NormalField, KernelTangentMatchesFiniteDifferences) {
  const double R = 0.06;
  const FaceX W = warped_quad();
  const FaceX T = cylinder_tri6(1.0);
  for (double g0 : {0.0, 0.01}) {
    const FacePoint fp = evaluate(FaceKind::Quad4, W, Vec2(0.3, -0.4));
    check_kernel(FaceKind::Quad4, W, BeamPoint{fp.x + 0.05 * fp.n, 0.3, R}, g0);
    check_kernel(FaceKind::Quad4, W, BeamPoint{fp.x - 0.02 * fp.n, 0.3, R}, g0);  // centre behind the surface
    const FacePoint tp = evaluate(FaceKind::Tri6, T, Vec2(0.25, 0.35));
    check_kernel(FaceKind::Tri6, T, BeamPoint{tp.x + 0.03 * tp.n, 0.1, R}, g0);
    FaceX T3(3, 3);
    T3 << 0, 0.3, 0.05, 0, 0.02, 0.25, 0, 0.01, -0.02;
    const FacePoint t3 = evaluate(FaceKind::Tri3, T3, Vec2(0.3, 0.3));
    check_kernel(FaceKind::Tri3, T3, BeamPoint{t3.x + 0.02 * t3.n, 0.05, R}, g0);
  }
}

// Consistency (continuity): a point moved across a groove (concave kink of 2 x 10 degrees). With the closest-
// point projection the line load jumps where the closest face changes (the two face normals); along the
// averaged field it changes by O(step): the largest change between neighbouring positions shrinks with the step.
TEST(NormalField, LineLoadContinuousAcrossGroove) {
  const double angle = 10.0 * M_PI / 180.0;
  test::Mesh m = groove(angle);
  SurfaceSearch S(m.surface, 0.3);
  S.enable_normal_field();
  S.update(m.x);
  const SurfaceSearch* one[] = {&S};
  auto max_jump = [&](bool averaged, int n) {
    LineContactParams par;
    par.penalty = 10.0;
    par.averaged_normals = averaged;
    par.compute_tangent = false;
    Vec3 last = Vec3::Zero();
    double jump = 0.0;
    for (int i = 0; i <= n; ++i) {
      const BeamPoint bp{Vec3(-0.05 + 0.1 * i / n, 0.1, 0.03), 0.01, 0.06};
      const LineContactResult res = evaluate_line_contact(std::span<const BeamPoint>(&bp, 1), one, par);
      EXPECT_EQ(res.diag.num_active, 1);
      if (i > 0) jump = std::max(jump, (res.q[0] - last).norm());
      last = res.q[0];
    }
    return jump;
  };
  const double q_scale = 10.0 * 0.03;  // eps * penetration
  // closest point: a jump of about 2 sin(angle) q, whatever the step
  EXPECT_GT(max_jump(false, 200), 0.2 * q_scale);
  EXPECT_GT(max_jump(false, 400), 0.2 * q_scale);
  // averaged field: O(step) changes
  const double j1 = max_jump(true, 200), j2 = max_jump(true, 400);
  EXPECT_LT(j1, 0.02 * q_scale);
  EXPECT_NEAR(j2 / j1, 0.5, 0.1);
}

// Compares against: central finite differences of the globally assembled residual on a perturbed quad cylinder
// and a curved tri6 patch: every node moved, nodal normals and projections recomputed, so the chain through the
// normals of the nodes around each face (NodeNormal::dn) is checked with the search and the assembly layout.
TEST(NormalField, AssembledTangentMatchesFiniteDifferences) {
  for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
    const test::Mesh m = perturbed_quarter_cylinder(kind, 3);
    const int n = static_cast<int>(m.x.size());
    const std::vector<BeamPoint> pts = helix_points();
    auto assemble = [&](const Eigen::VectorXd& u, Eigen::MatrixXd* K) {
      std::vector<Vec3> x(n);
      for (int i = 0; i < n; ++i) x[i] = u.segment<3>(3 * i);
      SurfaceSearch S(m.surface, 0.3);
      S.enable_normal_field();
      S.update(x);
      const SurfaceSearch* s[] = {&S};
      LineContactParams par;
      par.averaged_normals = true;
      par.regularization = 0.005;
      par.compute_tangent = K != nullptr;
      const LineContactResult res = evaluate_line_contact(pts, s, par);
      EXPECT_EQ(res.diag.num_active, 12);
      return assemble_dense(res.solid, n, K);
    };
    Eigen::VectorXd u(3 * n);
    for (int i = 0; i < n; ++i) u.segment<3>(3 * i) = m.x[i];
    Eigen::MatrixXd K;
    const Eigen::VectorXd r = assemble(u, &K);
    ASSERT_GT(r.norm(), 0.0);
    const Eigen::MatrixXd Kfd = fd_jacobian([&](const Eigen::VectorXd& v) { return assemble(v, nullptr); }, u, 1e-6);
    EXPECT_LT(rel_diff(K, Kfd), 1e-6) << name(kind);
  }
}

// Compares against: the exact (ring) tangent, whose columns are checked against finite differences above.
// Without the ring columns (LineContactParams::ring_tangent = false) every contribution keeps the face's own
// nodes, with exactly the ring tangent's columns of those nodes, and the same residual.
TEST(NormalField, FaceTangentIsTheRingTangentsFaceColumns) {
  for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
    const test::Mesh m = perturbed_quarter_cylinder(kind, 5);
    const std::vector<BeamPoint> pts = helix_points();
    SurfaceSearch S(m.surface, 0.3);
    S.enable_normal_field();
    S.update(m.x);
    const SurfaceSearch* s[] = {&S};
    LineContactParams par;
    par.averaged_normals = true;
    par.regularization = 0.005;
    const LineContactResult ring = evaluate_line_contact(pts, s, par);
    par.ring_tangent = false;
    const LineContactResult face = evaluate_line_contact(pts, s, par);
    ASSERT_EQ(ring.solid.size(), 12u);
    ASSERT_EQ(face.solid.size(), ring.solid.size());
    for (std::size_t i = 0; i < ring.solid.size(); ++i) {
      const NodalContribution &a = ring.solid[i], &b = face.solid[i];
      const Eigen::Index nn = b.r.size() / 3;
      EXPECT_GT(a.nodes.size(), std::size_t(nn)) << name(kind);  // the ring tangent reaches beyond the face
      ASSERT_EQ(b.nodes.size(), std::size_t(nn)) << name(kind);
      EXPECT_TRUE(std::equal(b.nodes.begin(), b.nodes.end(), a.nodes.begin())) << name(kind);
      EXPECT_EQ(b.r, a.r) << name(kind);
      EXPECT_EQ(b.K, a.K.leftCols(3 * nn)) << name(kind);
    }
  }
}

// The helix's points against a perturbed quarter cylinder of one face kind, searched along the averaged normal
// field or for the closest point; eval() with penalty 10 and the face's columns only unless `ring`.
struct HelixOnQuarterCylinder {
  test::Mesh m;
  std::vector<BeamPoint> pts;
  SurfaceSearch S;
  bool averaged;
  HelixOnQuarterCylinder(FaceKind kind, bool averaged_normals)
      : m(perturbed_quarter_cylinder(kind, 5)), pts(helix_points()), S(m.surface, 0.3), averaged(averaged_normals) {
    if (averaged) S.enable_normal_field();
    S.update(m.x);
  }
  HelixOnQuarterCylinder(const HelixOnQuarterCylinder&) = delete;  // S points into m
  HelixOnQuarterCylinder& operator=(const HelixOnQuarterCylinder&) = delete;
  LineContactResult eval(double g0, bool force, bool definite = false, bool ring = false) const {
    LineContactParams par;
    par.penalty = 10.0;
    par.averaged_normals = averaged;
    par.ring_tangent = ring;
    par.regularization = g0;
    par.force_tangent = force;
    par.definite_force_terms = definite;
    const SurfaceSearch* s[] = {&S};
    return evaluate_line_contact(pts, s, par);
  }
};

// Compares against: the exact tangent, which is affine in the penalty law's force f and stiffness k for one
// configuration. In the law's linear range (g <= 0) k = eps whatever the regularization g0, while f = eps (g0/2
// - g) moves with g0; so with LineContactParams::force_tangent = false (contact.line_tangent: gap) the tangent
// must not change with g0, what it leaves out of the exact one must be f times one matrix, and the residual
// must be the exact one's. For the averaged-normal kernel (face columns) and the closest-point kernel.
TEST(NormalField, GapTangentLeavesOutExactlyTheForceTerms) {
  for (bool averaged : {true, false})
    for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
      const HelixOnQuarterCylinder h(kind, averaged);
      auto eval = [&](double g0, bool force) { return h.eval(g0, force); };
      const double g1 = 0.002, g2 = 0.01;  // both below the points' penetration (about 0.02 mm): linear range
      const LineContactResult e1 = eval(g1, true), e2 = eval(g2, true), p1 = eval(g1, false), p2 = eval(g2, false);
      ASSERT_EQ(e1.solid.size(), 12u);
      ASSERT_EQ(p1.solid.size(), 12u);
      ASSERT_EQ(p2.solid.size(), 12u);
      for (std::size_t i = 0; i < e1.solid.size(); ++i) {
        const int pt = e1.solid[i].point;
        const double g = e1.per_surface[0][pt].gap;
        ASSERT_LT(g, 0.0) << name(kind);
        const auto l1 = angio::participant::penalty_law(g, g1, 10.0), l2 = angio::participant::penalty_law(g, g2, 10.0);
        ASSERT_EQ(l1.k, l2.k) << name(kind);  // the linear range: one stiffness, two forces
        const double f1 = l1.f, f2 = l2.f;
        EXPECT_EQ(p1.solid[i].r, e1.solid[i].r) << name(kind);
        EXPECT_EQ(p1.solid[i].nodes, e1.solid[i].nodes) << name(kind);
        const Eigen::MatrixXd& K = p1.solid[i].K;
        EXPECT_LT((p2.solid[i].K - K).norm(), 1e-12 * K.norm()) << name(kind) << " averaged " << averaged;
        const Eigen::MatrixXd B1 = (e1.solid[i].K - K) / f1, B2 = (e2.solid[i].K - K) / f2;
        EXPECT_GT(B1.norm(), 1e-3 * K.norm() / f1) << name(kind);  // the force's terms are there to leave out
        EXPECT_LT((B1 - B2).norm(), 1e-9 * B1.norm()) << name(kind) << " averaged " << averaged;
      }
    }
}

// Compares against: the definition of the projection onto the positive semidefinite cone. With
// LineContactParams::definite_force_terms (contact.line_tangent: definite) the tangent is K_gap + P, P the
// positive semidefinite part of the symmetric part S of the force's terms K_f = K_exact - K_gap (face columns).
// P is that projection exactly when P >= 0, P - S >= 0 and P (P - S) = 0 (the two parts' eigenvectors split the
// space). The residual is the exact one's; where S has negative eigenvalues (checked: the case the option is for)
// P differs from S. For the averaged-normal kernel and the closest-point kernel. Asked for the ring's columns
// too, the definite tangent stays over the face's own nodes (the same contribution). Round-off: P and S are
// differences of tangents of norm |K|, so the properties hold to a small multiple of eps |K|.
TEST(NormalField, DefiniteTangentKeepsThePositivePartOfTheForceTerms) {
  for (bool averaged : {true, false})
    for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
      const HelixOnQuarterCylinder h(kind, averaged);  // face columns: the definite tangent has no others
      const LineContactResult exact = h.eval(0.005, true), gap = h.eval(0.005, false), def = h.eval(0.005, true, true);
      const LineContactResult def_ring = h.eval(0.005, true, true, true);
      ASSERT_EQ(def.solid.size(), 12u);
      ASSERT_EQ(exact.solid.size(), def.solid.size());
      ASSERT_EQ(gap.solid.size(), def.solid.size());
      ASSERT_EQ(def_ring.solid.size(), def.solid.size());
      int indefinite = 0;
      for (std::size_t i = 0; i < def.solid.size(); ++i) {
        const NodalContribution &d = def.solid[i], &g = gap.solid[i], &e = exact.solid[i];
        EXPECT_EQ(d.r, e.r) << name(kind);
        EXPECT_EQ(d.nodes, g.nodes) << name(kind);
        EXPECT_EQ(def_ring.solid[i].nodes, d.nodes) << name(kind);
        EXPECT_EQ(def_ring.solid[i].K, d.K) << name(kind);
        ASSERT_EQ(d.K.rows(), d.K.cols()) << name(kind);
        ASSERT_EQ(e.K.cols(), g.K.cols()) << name(kind);
        const Eigen::MatrixXd Kf = e.K - g.K;
        const Eigen::MatrixXd Sf = 0.5 * (Kf + Kf.transpose());
        const Eigen::MatrixXd P = d.K - g.K;
        const double scale = std::max({Sf.norm(), e.K.norm(), g.K.norm()});
        ASSERT_GT(Sf.norm(), 0.0);
        EXPECT_LT((P - P.transpose()).norm(), 1e-12 * scale) << name(kind);
        const Eigen::MatrixXd Psym = 0.5 * (P + P.transpose());
        const Eigen::MatrixXd Q = 0.5 * ((P - Sf) + (P - Sf).transpose());
        EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Psym).eigenvalues().minCoeff(), -1e-12 * scale);
        EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Q).eigenvalues().minCoeff(), -1e-12 * scale);
        EXPECT_LT((P * (P - Sf)).norm(), 1e-12 * scale * scale) << name(kind);
        if (Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Sf).eigenvalues().minCoeff() < -1e-6 * Sf.norm()) {
          ++indefinite;
          EXPECT_GT((P - Sf).norm(), 1e-6 * Sf.norm()) << name(kind);
        }
      }
      EXPECT_GT(indefinite, 0) << name(kind) << " averaged " << averaged;  // the case the option is for
    }
}

// Consistency: an update without the normals' derivatives (what a residual-only evaluation asks for) gives the
// same normals, residual and loads as one with them, and a tangent from it is refused instead of being built
// from stale derivatives.
TEST(NormalField, UpdateWithoutDerivativesSameResidualTangentRefused) {
  const test::Mesh m = perturbed_quarter_cylinder(FaceKind::Quad4, 7);
  const std::vector<BeamPoint> pts = helix_points();
  SurfaceSearch full(m.surface, 0.3), bare(m.surface, 0.3);
  full.enable_normal_field();
  bare.enable_normal_field();
  full.update(m.x);
  bare.update(m.x, true, false);
  EXPECT_TRUE(full.normal_derivatives());
  EXPECT_FALSE(bare.normal_derivatives());
  LineContactParams par;
  par.averaged_normals = true;
  par.regularization = 0.005;
  par.compute_tangent = false;
  const SurfaceSearch* a[] = {&full};
  const SurfaceSearch* b[] = {&bare};
  const LineContactResult ra = evaluate_line_contact(pts, a, par), rb = evaluate_line_contact(pts, b, par);
  ASSERT_EQ(ra.solid.size(), 12u);
  ASSERT_EQ(rb.solid.size(), ra.solid.size());
  for (std::size_t i = 0; i < ra.solid.size(); ++i) EXPECT_EQ(rb.solid[i].r, ra.solid[i].r);
  EXPECT_EQ(rb.q, ra.q);
  par.compute_tangent = true;
  EXPECT_THROW(evaluate_line_contact(pts, b, par), std::logic_error);
  EXPECT_NO_THROW(evaluate_line_contact(pts, a, par));
}

// Consistency: a projection hint changes where the search starts, not what it finds. For random points
// around a perturbed quarter cylinder (quad4 and tri6), the hinted projection equals the unhinted one (face,
// found, d and s to the projection's Newton tolerance) for a hint at the answer, at a neighbouring face, at a
// face out of range, with parameters far outside its face, and for no face; with the hint at the answer, the
// projection restarts there and converges in at most two Newton iterations (from the centre: more).
TEST(NormalField, HintedProjectionEqualsUnhinted) {
  for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
    const test::Mesh m = perturbed_quarter_cylinder(kind, 11);
    SurfaceSearch S(m.surface, 0.3);
    S.enable_normal_field();
    S.update(m.x);
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> U(0, 1);
    const int nf = int(m.surface.faces.size());
    int found = 0, restarted = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 x = cyl(0.4 + 0.3 * U(rng), 0.1 + 1.35 * U(rng), 0.05 + 0.5 * U(rng));
      const SurfaceNormalProjection ref = S.along_normals(x);
      std::vector<ProjectionHint> hints = {{ref.found ? ref.face : -1, ref.proj.xi},
                                           {ref.found ? (ref.face + 1) % nf : 0, Vec2(0.1, 0.1)},
                                           {nf + 3, Vec2::Zero()},
                                           {(i * 7) % nf, Vec2(5.0, -4.0)},
                                           {-1, Vec2::Zero()}};
      for (std::size_t h = 0; h < hints.size(); ++h) {
        const SurfaceNormalProjection p = S.along_normals(x, 1e-10, &hints[h]);
        ASSERT_EQ(p.found, ref.found) << "point " << i << " hint " << h;
        if (!ref.found) continue;
        EXPECT_EQ(p.face, ref.face) << "point " << i << " hint " << h;
        EXPECT_NEAR(p.proj.d, ref.proj.d, 1e-12);
        EXPECT_LT((p.proj.s - ref.proj.s).norm(), 1e-12);
        if (h == 0) {
          EXPECT_LE(p.proj.iterations, 2);
          restarted += ref.proj.iterations > 2;
        }
      }
      found += ref.found;
    }
    EXPECT_GT(found, 100);
    EXPECT_GT(restarted, 50);  // from the centre the same projections take more iterations
  }
}

// Consistency: evaluate_line_contact with projection hints gives the residual and tangent of the evaluation
// without (to the projection's Newton tolerance), fills one hint per found point, and keeps doing so when
// the surface has moved since the hints were written (the second evaluation starts from stale hints).
TEST(NormalField, LineContactWithHintsEqualsWithout) {
  for (FaceKind kind : {FaceKind::Quad4, FaceKind::Tri6}) {
    test::Mesh m = perturbed_quarter_cylinder(kind, 9);
    const int n = static_cast<int>(m.x.size());
    const std::vector<BeamPoint> pts = helix_points();
    std::vector<ProjectionHint> hints(pts.size());
    const std::span<ProjectionHint> h[] = {hints};
    LineContactParams par;
    par.averaged_normals = true;
    par.regularization = 0.005;
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1)
        for (Vec3& x : m.x) x *= 1.01;  // the surface moves toward the points: stale hints
      SurfaceSearch S(m.surface, 0.3);
      S.enable_normal_field();
      S.update(m.x);
      const SurfaceSearch* s[] = {&S};
      const LineContactResult plain = evaluate_line_contact(pts, s, par);
      const LineContactResult hinted = evaluate_line_contact(pts, s, par, h);
      Eigen::MatrixXd K0, K1;
      const Eigen::VectorXd r0 = assemble_dense(plain.solid, n, &K0), r1 = assemble_dense(hinted.solid, n, &K1);
      ASSERT_GT(r0.norm(), 0.0);
      EXPECT_LT((r1 - r0).norm(), 1e-12 * r0.norm()) << name(kind) << " pass " << pass;
      EXPECT_LT((K1 - K0).norm(), 1e-12 * K0.norm()) << name(kind) << " pass " << pass;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const PointContact& pc = plain.per_surface[0][i];
        EXPECT_EQ(hints[i].face, pc.found ? pc.face : -1);
        if (pc.found) {
          EXPECT_LT((hints[i].xi - pc.proj.xi).norm(), 1e-12);
        }
      }
      // hints of another shape are refused, not ignored
      const std::span<ProjectionHint> short_hints[] = {std::span(hints).first(pts.size() - 1)};
      const std::span<ProjectionHint> two[] = {hints, hints};
      EXPECT_THROW(evaluate_line_contact(pts, s, par, short_hints), std::invalid_argument);
      EXPECT_THROW(evaluate_line_contact(pts, s, par, two), std::invalid_argument);
    }
  }
}
