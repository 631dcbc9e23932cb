// Line-to-surface penalty contact: beam points against solid surfaces.
#include <gtest/gtest.h>

#include "angio/participant/penalty_law.hpp"
#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

namespace {
// FD check of the solid tangent: K = d r / dX with the beam point fixed (r = dPi/dX = -forces).
void check_tangent(FaceKind k, const FaceX& X, double sign, const BeamPoint& bp, double eps = 10.0, double g0 = 0.0) {
  LineContactParams par;
  par.penalty = eps;
  par.regularization = g0;
  par.beam_tangent = true;
  const Projection p = project(k, X, sign, bp.x);
  PointContact pc;
  Eigen::VectorXd r;
  Eigen::MatrixXd K;
  line_point_kernel(bp, k, X, sign, p, par, pc, r, &K);
  ASSERT_TRUE(pc.active);
  auto res = [&](const Eigen::VectorXd& v) {
    const FaceX XX = unflatten(v);
    const Projection q = project(k, XX, sign, bp.x);
    EXPECT_EQ(q.location, p.location);
    PointContact c;
    Eigen::VectorXd rr;
    line_point_kernel(bp, k, XX, sign, q, par, c, rr, nullptr);
    return rr;
  };
  const Eigen::MatrixXd Kfd = fd_jacobian(res, flatten(X), 1e-6);
  EXPECT_LT(rel_diff(K, Kfd), 1e-6) << name(k) << " " << name(p.location);
  EXPECT_LT(rel_diff(K, K.transpose()), 1e-12);
  // beam-side tangent dq/dx (robin data) vs FD with the face fixed
  auto qx = [&](const Eigen::VectorXd& v) {
    BeamPoint b = bp;
    b.x = v;
    const Projection q = project(k, X, sign, b.x);
    PointContact c;
    Eigen::VectorXd rr;
    line_point_kernel(b, k, X, sign, q, par, c, rr, nullptr);
    return Eigen::VectorXd(c.q);
  };
  EXPECT_LT(rel_diff(pc.dq_dx, fd_jacobian(qx, bp.x, 1e-6)), 1e-6);
  // force balance: sum of solid nodal forces (-r) = -w q
  Vec3 fsum = Vec3::Zero();
  for (int a = 0; a < num_nodes(k); ++a) fsum -= r.segment<3>(3 * a);
  EXPECT_LT((fsum + bp.w * pc.q).norm(), 1e-13 * (1 + bp.w * pc.q.norm()));
}
}  // namespace

// Compares against: the analytic penalty force eps * penetration * w along the face normal, distributed with
// the bilinear shape functions; and the tangent against central finite differences.
TEST(LineContact, PointPressedIntoFlatQuad) {
  FaceX X(3, 4);
  X << 0, 1, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0;
  const double eps = 10.0, R = 0.06, w = 0.2, pen = 0.01;
  BeamPoint bp{Vec3(0.25, 0.5, R - pen), w, R};
  const Projection p = project(FaceKind::Quad4, X, 1.0, bp.x);
  LineContactParams par;
  par.penalty = eps;
  PointContact pc;
  Eigen::VectorXd r;
  Eigen::MatrixXd K;
  line_point_kernel(bp, FaceKind::Quad4, X, 1.0, p, par, pc, r, &K);
  EXPECT_TRUE(pc.active);
  EXPECT_NEAR(pc.gap, -pen, 1e-15);
  EXPECT_NEAR((pc.q - Vec3(0, 0, eps * pen)).norm(), 0, 1e-14);  // beam pushed along +n
  const double N[4] = {0.375, 0.125, 0.125, 0.375};              // bilinear N at (0.25, 0.5)
  for (int a = 0; a < 4; ++a) EXPECT_NEAR((-r.segment<3>(3 * a) - Vec3(0, 0, -eps * pen * w * N[a])).norm(), 0, 1e-15);
  check_tangent(FaceKind::Quad4, X, 1.0, bp, eps);
  // separated point: no force
  bp.x.z() = R + 0.001;
  line_point_kernel(bp, FaceKind::Quad4, X, 1.0, project(FaceKind::Quad4, X, 1.0, bp.x), par, pc, r, &K);
  EXPECT_FALSE(pc.active);
  EXPECT_EQ(r.norm(), 0.0);
}

// Compares against: central finite differences of the residual (curved/warped faces, edges, corners, both
// normal signs) and global force balance sum_a f_a = -w q.
TEST(LineContact, TangentCurvedFacesMatchesFiniteDifferences) {
  const double R = 0.06;
  const FaceX W = warped_quad();
  const FaceX T = cylinder_tri6(1.0);
  {
    const FacePoint fp = evaluate(FaceKind::Quad4, W, Vec2(0.3, 0.4));
    check_tangent(FaceKind::Quad4, W, 1.0, BeamPoint{fp.x + 0.04 * fp.n, 0.3, R});
    check_tangent(FaceKind::Quad4, W, -1.0, BeamPoint{fp.x - 0.05 * fp.n, 0.3, R});
    check_tangent(FaceKind::Quad4, W, 1.0, BeamPoint{fp.x - 0.02 * fp.n, 0.3, R});  // centre behind the surface
  }
  {
    const FacePoint tp = evaluate(FaceKind::Tri6, T, Vec2(0.25, 0.35));
    check_tangent(FaceKind::Tri6, T, 1.0, BeamPoint{tp.x + 0.03 * tp.n, 0.1, R});   // balloon: beam outside
    check_tangent(FaceKind::Tri6, T, -1.0, BeamPoint{tp.x - 0.03 * tp.n, 0.1, R});  // lumen: beam inside
  }
  {  // tri3 (flat: the tangent has only the closest-point sliding terms)
    FaceX T3(3, 3);
    T3 << 0, 0.3, 0.05, 0, 0.02, 0.25, 0, 0.01, -0.02;
    const FacePoint tp = evaluate(FaceKind::Tri3, T3, Vec2(0.3, 0.3));
    check_tangent(FaceKind::Tri3, T3, 1.0, BeamPoint{tp.x + 0.02 * tp.n, 0.05, R});
  }
  {  // edge and corner projections
    const FacePoint ep = evaluate(FaceKind::Quad4, W, Vec2(1.05, 0.2));
    check_tangent(FaceKind::Quad4, W, 1.0, BeamPoint{ep.x + 0.03 * ep.n, 0.2, R});
    const FacePoint cp = evaluate(FaceKind::Quad4, W, Vec2(1.04, 1.03));
    check_tangent(FaceKind::Quad4, W, 1.0, BeamPoint{cp.x + 0.03 * cp.n, 0.2, R});
    const FacePoint tp = evaluate(FaceKind::Tri6, T, Vec2(-0.04, 0.5));
    check_tangent(FaceKind::Tri6, T, 1.0, BeamPoint{tp.x + 0.03 * tp.n, 0.2, R});
  }
}

// Compares against: Newton's third law over a whole surface: the sum of all solid nodal forces equals
// -sum_i w_i q_i (to round-off) on a distorted, curved mesh; and diag.force_on_solid.
TEST(LineContact, GlobalForceBalanceDistortedCylinder) {
  Mesh m = cylinder(FaceKind::Quad4, 0.5, 2.0, 16, 8);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (Vec3& p : m.x) p += 0.02 * Vec3(U(rng), U(rng), U(rng));  // distort (warped quads)
  SurfaceSearch S(m.surface, 0.3);
  S.update(m.x);
  std::vector<BeamPoint> pts;
  for (int i = 0; i < 200; ++i) {
    const double th = M_PI * (U(rng) + 1), z = 1.0 + 0.8 * U(rng);
    pts.push_back({cyl(0.5 + 0.06 + 0.03 * U(rng), th, z), 0.05 + 0.02 * U(rng), 0.06});
  }
  const SurfaceSearch* surfs[] = {&S};
  const LineContactResult res = evaluate_line_contact(pts, surfs, LineContactParams{});
  EXPECT_GT(res.diag.num_active, 40);
  Vec3 beam = Vec3::Zero(), solid = Vec3::Zero();
  for (std::size_t i = 0; i < pts.size(); ++i) beam += pts[i].w * res.q[i];
  for (const NodalContribution& c : res.solid)
    for (Eigen::Index a = 0; a < c.r.size() / 3; ++a) solid -= c.r.segment<3>(3 * a);
  EXPECT_LT((solid + beam).norm(), 1e-13 * beam.norm() + 1e-15);
  EXPECT_LT((res.diag.force_on_solid - solid).norm(), 1e-13 * beam.norm());
  EXPECT_LT(res.diag.min_gap, 0.0);
}

// Compares against: continuity of the gap (and of q) along a path: max jump between successive samples
// is bounded by (gap slope) x step. Two coplanar quads, two quads with a convex kink, and across a tri6 edge.
TEST(LineContact, SlidingAcrossFaceBoundariesContinuousGap) {
  const double R = 0.06;
  double normal_jump = 0;  // largest change of the contact normal between successive samples
  auto run = [&](const Mesh& m, const std::function<Vec3(double)>& path, double t0, double t1, int& changes) {
    SurfaceSearch S(m.surface, 0.5);
    S.update(m.x);
    double prev = 0;
    Vec3 prev_n = Vec3::Zero();
    int prev_face = -1;
    const int n = 2000;
    changes = 0;
    double maxjump = 0;
    normal_jump = 0;
    for (int i = 0; i <= n; ++i) {
      const Vec3 x = path(t0 + (t1 - t0) * i / n);
      const SurfaceProjection sp = S.closest(x);
      EXPECT_TRUE(sp.found);
      const double g = sp.proj.d - R;
      if (i > 0) maxjump = std::max(maxjump, std::abs(g - prev));
      if (i > 0) normal_jump = std::max(normal_jump, (sp.proj.n - prev_n).norm());
      if (i > 0 && sp.face != prev_face) ++changes;
      prev = g;
      prev_n = sp.proj.n;
      prev_face = sp.face;
    }
    return maxjump / ((t1 - t0) / n);  // ~ |dg/dt|, bounded if continuous
  };
  int changes = 0;
  {  // coplanar quads: gap constant
    Mesh m = flat_quads(2, 1, 1.0, 1.0);
    const double slope = run(
        m, [](double t) { return Vec3(t, 0.4, 0.05); }, 0.2, 1.8, changes);
    EXPECT_LT(slope, 1e-9);
    EXPECT_GE(changes, 1);
    EXPECT_LT(normal_jump, 1e-12);
  }
  {  // convex kink (roof): second quad tilted down by 20 degrees about x = 1
    Mesh m = flat_quads(2, 1, 1.0, 1.0);
    const double a = 20 * M_PI / 180;
    for (Vec3& p : m.x)
      if (p.x() > 1.5) p = Vec3(1 + std::cos(a), p.y(), -std::sin(a));
    const double slope = run(
        m, [](double t) { return Vec3(t, 0.4, 0.04); }, 0.5, 1.5, changes);
    EXPECT_LT(slope, 1.0 + 1e-6);  // |dg/dx| <= 1 for a distance function
    EXPECT_GE(changes, 1);
    // the point-to-edge normal turns continuously over the kink: rate <= 1/height per unit path length
    EXPECT_LT(normal_jump, 1.1 * (1.0 / 2000) / 0.04);
  }
  {  // tri6 cylinder: circumferential path crossing quad-diagonal and element edges, outside the balloon
    Mesh m = cylinder(FaceKind::Tri6, 0.5, 1.0, 12, 2);
    const double slope = run(
        m, [](double t) { return cyl(0.55, t, 0.3 + 0.1 * t); }, 0.1, 2.0, changes);
    EXPECT_LT(slope, 0.2);
    EXPECT_GE(changes, 3);
    // from inside (lumen-like view with normal_sign = -1)
    m.surface.normal_sign = -1.0;
    const double slope2 = run(
        m, [](double t) { return cyl(0.45, t, 0.3 + 0.1 * t); }, 0.1, 2.0, changes);
    EXPECT_LT(slope2, 0.2);
  }
}

// Compares against: superposition — a point squeezed between a balloon (beam outside, normal_sign +1) and an
// artery lumen (beam inside, normal_sign -1) receives the sum of both single-surface line loads.
TEST(LineContact, TwoSurfacesSum) {
  const double R = 0.06;
  Mesh balloon = cylinder(FaceKind::Quad4, 1.0, 2.0, 32, 4);
  Mesh artery = cylinder(FaceKind::Tri6, 1.1, 2.0, 32, 4);
  artery.surface.normal_sign = -1.0;  // endothelium: normal into the lumen (toward the beam)
  // one coordinate array for both (as in the solid solver's appended mesh)
  Mesh all = balloon;
  const int off = static_cast<int>(all.x.size());
  all.x.insert(all.x.end(), artery.x.begin(), artery.x.end());
  Surface art = artery.surface;
  for (Face& f : art.faces)
    for (int a = 0; a < f.nn(); ++a) f.nodes[a] += off;
  SurfaceSearch Sb(all.surface, 0.2), Sa(art, 0.2);
  Sb.update(all.x);
  Sa.update(all.x);
  const double th = 2 * M_PI * 5 / 32;  // on a node line of both meshes: the facets pass exactly through r = 1, 1.1
  const std::vector<BeamPoint> pts = {{cyl(1.05, th, 1.0), 0.1, R}, {cyl(1.2, th, 1.0), 0.1, R}};
  const SurfaceSearch* both[] = {&Sb, &Sa};
  const SurfaceSearch* only_b[] = {&Sb};
  const SurfaceSearch* only_a[] = {&Sa};
  const LineContactParams par;
  const auto rb = evaluate_line_contact(pts, only_b, par);
  const auto ra = evaluate_line_contact(pts, only_a, par);
  const auto r2 = evaluate_line_contact(pts, both, par);
  EXPECT_LT((r2.q[0] - rb.q[0] - ra.q[0]).norm(), 1e-14);
  EXPECT_EQ(r2.diag.num_active, 3);                         // point 0 touches both surfaces, point 1 only the artery
  EXPECT_GT(rb.q[0].dot(cyl(1, th, 0).normalized()), 0.0);  // balloon pushes outward
  EXPECT_LT(ra.q[0].dot(cyl(1, th, 0).normalized()), 0.0);  // artery pushes inward
  EXPECT_NEAR(rb.q[0].norm(), 10.0 * (R - 0.05), 1e-9);     // faceted balloon: exact at the node line
  EXPECT_NEAR(ra.q[0].norm(), 10.0 * (R - 0.05), 1e-2);     // tri6 artery: ~1e-4 mm geometric error
  EXPECT_TRUE(r2.per_surface[1][1].found);  // second point: inside the artery wall by 0.1 - R (penetrates)
  EXPECT_TRUE(r2.per_surface[1][1].active);
  EXPECT_FALSE(r2.per_surface[0][1].active);
  EXPECT_LT((r2.force_on_beam - 0.1 * (r2.q[0] + r2.q[1])).norm(), 1e-15);
  // robin data: the surface with the smallest gap per point
  const auto rp = robin_points(r2, 10.0);
  ASSERT_EQ(rp.size(), 2u);
  EXPECT_TRUE(rp[1].active);
  EXPECT_EQ(rp[1].surface, 1);
  EXPECT_NEAR(rp[1].gap, r2.per_surface[1][1].gap, 0.0);
  EXPECT_EQ(rp[1].penalty, 10.0);
  EXPECT_LT((rp[1].n + cyl(1, th, 0).normalized()).norm(), 1e-2);
}

// Compares against: central finite differences of the globally assembled residual (all nodes of a curved tri6
// mesh perturbed, closest points re-searched) — checks the whole pipeline (search, node ids, assembly layout).
TEST(LineContact, AssembledTangentMatchesFiniteDifferences) {
  Mesh m = cylinder(FaceKind::Tri6, 0.5, 1.0, 8, 2, 0.0, M_PI / 2);
  const int n = static_cast<int>(m.x.size());
  std::vector<BeamPoint> pts;
  for (int i = 0; i < 6; ++i) pts.push_back({cyl(0.54, 0.17 + 0.23 * i, 0.13 + 0.14 * i), 0.07, 0.06});
  double energy = 0;
  auto assemble = [&](const Eigen::VectorXd& u, Eigen::MatrixXd* K) {
    std::vector<Vec3> x(n);
    for (int i = 0; i < n; ++i) x[i] = u.segment<3>(3 * i);
    SurfaceSearch S(m.surface, 0.2);
    S.update(x);
    const SurfaceSearch* s[] = {&S};
    LineContactParams par;
    par.compute_tangent = K != nullptr;
    const LineContactResult res = evaluate_line_contact(pts, s, par);
    energy = res.diag.energy;
    return assemble_dense(res.solid, n, K);
  };
  Eigen::VectorXd u(3 * n);
  for (int i = 0; i < n; ++i) u.segment<3>(3 * i) = m.x[i];
  // tangent = FD Jacobian; the residual is the gradient of the penalty potential Pi = sum w eps/2 <g>^2
  Eigen::VectorXd r;
  expect_fd_consistent(assemble, energy, u, r);
}

// Linear-quadratic (C¹) penalty law: compares against its closed form q = eps (g0/2 − g) for g ≤ 0,
// eps (g0 − g)²/(2 g0) for 0 < g < g0, 0 beyond (continuous force and stiffness at g = 0 and at
// g0), and the tangents against central finite differences in both branches.
TEST(LineContact, LinearQuadraticLawMatchesClosedFormAndTangents) {
  FaceX X(3, 4);
  X << 0, 1, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0;
  const double eps = 10.0, R = 0.06, w = 0.2, g0 = 0.004;
  LineContactParams par;
  par.penalty = eps;
  par.regularization = g0;
  auto force = [&](double g) {
    BeamPoint bp{Vec3(0.3, 0.6, R + g), w, R};
    PointContact pc;
    Eigen::VectorXd r;
    line_point_kernel(bp, FaceKind::Quad4, X, 1.0, project(FaceKind::Quad4, X, 1.0, bp.x), par, pc, r, nullptr);
    return pc.q.z();
  };
  EXPECT_NEAR(force(-0.01), eps * (0.5 * g0 + 0.01), 1e-14);
  EXPECT_NEAR(force(0.001), 0.5 * eps * (g0 - 0.001) * (g0 - 0.001) / g0, 1e-15);
  EXPECT_EQ(force(g0 + 1e-6), 0.0);
  EXPECT_NEAR(force(-1e-9), force(1e-9), 1e-7);  // continuous at g = 0
  // stiffness continuous at 0 (one-sided slopes −eps and −eps (1 − h/g0): difference O(eps h/g0))
  EXPECT_NEAR((force(1e-7) - force(-1e-7)) / 2e-7, -eps, 1e-3);
  check_tangent(FaceKind::Quad4, X, 1.0, BeamPoint{Vec3(0.3, 0.6, R - 0.01), w, R}, eps, g0);
  check_tangent(FaceKind::Quad4, X, 1.0, BeamPoint{Vec3(0.3, 0.6, R + 0.002), w, R}, eps, g0);
}

// The one penalty law (shared with the robin planes): f = −dπ/dg and k = −df/dg by central
// differences on both branches, continuity of π, f, k at g = 0 and zero force at g = g0 (C¹ law).
TEST(PenaltyLaw, DerivativesAndContinuity) {
  using angio::participant::penalty_law;
  const double eps = 10.0, h = 1e-6;
  for (double g0 : {0.0, 0.005}) {
    for (double g : {-0.02, -0.003, 0.001, 0.004}) {
      if (!(g < g0)) continue;
      const auto l = penalty_law(g, g0, eps), lp = penalty_law(g + h, g0, eps), lm = penalty_law(g - h, g0, eps);
      EXPECT_NEAR(l.f, -(lp.pi - lm.pi) / (2 * h), 1e-7 * eps) << "g0 " << g0 << " g " << g;
      EXPECT_NEAR(l.k, -(lp.f - lm.f) / (2 * h), 1e-6 * eps) << "g0 " << g0 << " g " << g;
    }
  }
  const double g0 = 0.005;
  const auto below = penalty_law(-1e-12, g0, eps), above = penalty_law(1e-12, g0, eps);
  EXPECT_NEAR(below.pi, above.pi, 1e-12);
  EXPECT_NEAR(below.f, above.f, 1e-10);
  EXPECT_NEAR(below.k, above.k, 1e-8);
  const auto end = penalty_law(g0, g0, eps);
  EXPECT_DOUBLE_EQ(end.f, 0.0);
  EXPECT_DOUBLE_EQ(end.pi, 0.0);
  EXPECT_DOUBLE_EQ(penalty_law(-0.01, 0.0, eps).f, 0.1);  // linear law: ε |g|
}

// penalty_gap inverts penalty_law on both branches (round trip g -> f -> g) and returns the edge of
// contact for no force.
TEST(PenaltyLaw, GapOfAForceInvertsTheLaw) {
  using angio::participant::penalty_gap;
  using angio::participant::penalty_law;
  for (double eps : {0.3, 10.0})
    for (double g0 : {0.0, 0.005})
      for (double g : {-0.02, -0.003, -1e-5, 0.001, 0.0049}) {
        if (!(g < g0)) continue;
        EXPECT_NEAR(penalty_gap(penalty_law(g, g0, eps).f, g0, eps), g, 1e-12) << "eps " << eps << " g0 " << g0;
      }
  EXPECT_EQ(penalty_gap(0.0, 0.005, 10.0), 0.005);
  EXPECT_EQ(penalty_gap(0.0, 0.0, 10.0), 0.0);
}
