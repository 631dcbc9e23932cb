// Surface-to-surface (Gauss-point-to-segment) penalty contact.
#include <gtest/gtest.h>

#include <algorithm>

#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

namespace {
// Slave patch facing -z (clockwise seen from +z): flip node order of flat_quads.
Mesh flipped(Mesh m) {
  for (Face& f : m.surface.faces) std::swap(f.nodes[1], f.nodes[3]);
  return m;
}

struct TwoPatches {
  Mesh all;
  Surface slave, master;
};

// master: [0,2]^2 in z = 0 (normal +z, 4x4 quads); slave: [x0,x1] x [y0,y1] at z = -pen (normal -z, nx x ny quads)
TwoPatches two_patches(double x0, double x1, double y0, double y1, int nx, int ny, double pen) {
  TwoPatches t;
  Mesh master = flat_quads(4, 4, 0.5, 0.5, 0.0);
  Mesh slave = flipped(flat_quads(nx, ny, (x1 - x0) / nx, (y1 - y0) / ny, -pen, x0, y0));
  t.all.x = master.x;
  t.master = master.surface;
  const int off = static_cast<int>(t.all.x.size());
  t.all.x.insert(t.all.x.end(), slave.x.begin(), slave.x.end());
  t.slave = slave.surface;
  for (Face& f : t.slave.faces)
    for (int a = 0; a < 4; ++a) f.nodes[a] += off;
  return t;
}

Vec3 net_force(const SurfaceContactResult& r, const std::vector<int>& nodes_filter, bool in_filter, int n_total) {
  std::vector<char> sel(n_total, 0);
  for (int i : nodes_filter) sel[i] = 1;
  Vec3 f = Vec3::Zero();
  for (const auto& c : r.contributions)
    for (std::size_t a = 0; a < c.nodes.size(); ++a)
      if (static_cast<bool>(sel[c.nodes[a]]) == in_filter) f -= c.r.segment<3>(3 * a);
  return f;
}
}  // namespace

namespace {
// Contact of the slave patch against the master patch of `t`, the searches updated to its coordinates.
SurfaceContactResult patches_contact(const TwoPatches& t, const SurfaceContactParams& par) {
  SurfaceSearch Ss(t.slave, 0.1), Sm(t.master, 0.1);
  Ss.update(t.all.x);
  Sm.update(t.all.x);
  return evaluate_surface_contact(Ss, Sm, par);
}
}  // namespace

// Compares against: the exact total force eps * penetration * overlap area for two parallel flat patches
// (non-matching meshes, slave fully inside the master), and equal and opposite forces on the two sides.
TEST(SurfaceContact, ParallelPatchesExactForceAndBalance) {
  const double eps = 5.0, pen = 0.01;
  TwoPatches t = two_patches(0.5, 1.5, 0.3, 1.7, 3, 5, pen);
  SurfaceContactParams par;
  par.penalty = eps;
  const SurfaceContactResult r = patches_contact(t, par);
  const double area = 1.0 * 1.4;
  EXPECT_EQ(r.diag.num_active, 15 * 4);
  EXPECT_NEAR(r.active_area, area, 1e-13);
  EXPECT_NEAR(r.diag.min_gap, -pen, 1e-15);
  std::vector<int> master_nodes(25);
  std::iota(master_nodes.begin(), master_nodes.end(), 0);
  const int n = static_cast<int>(t.all.x.size());
  const Vec3 fm = net_force(r, master_nodes, true, n), fs = net_force(r, master_nodes, false, n);
  EXPECT_NEAR(fm.z(), -eps * pen * area, 1e-14);  // master pushed away from the slave (-z)
  EXPECT_NEAR(fs.z(), eps * pen * area, 1e-14);
  EXPECT_LT((fm + fs).norm(), 1e-15);
  EXPECT_NEAR(r.diag.force_on_solid.z(), -eps * pen * area, 1e-14);
  for (const auto& gp : r.points) EXPECT_NEAR(gp.pressure, eps * pen, 1e-14);
}

// Compares against: the same exact force eps * pen * area with the symmetric two-pass variant (footprint aligned
// with the master mesh so both passes integrate the overlap exactly; master points beyond the slave's free rim
// are rejected).
TEST(SurfaceContact, TwoPassParallelPatches) {
  const double eps = 5.0, pen = 0.02;
  TwoPatches t = two_patches(0.5, 1.5, 0.5, 1.5, 3, 3, pen);
  SurfaceContactParams par;
  par.penalty = eps;
  par.two_pass = true;
  const SurfaceContactResult r = patches_contact(t, par);
  std::vector<int> master_nodes(25);
  std::iota(master_nodes.begin(), master_nodes.end(), 0);
  const int n = static_cast<int>(t.all.x.size());
  const Vec3 fm = net_force(r, master_nodes, true, n), fs = net_force(r, master_nodes, false, n);
  EXPECT_NEAR(fm.z(), -eps * pen * 1.0, 1e-13);
  EXPECT_LT((fm + fs).norm(), 1e-14);
}

namespace {
// Sum of the Gauss point kernels of one slave face against one master face.
Eigen::VectorXd pair_residual(FaceKind sk, const FaceX& Xs, FaceKind mk, const FaceX& Xm, double msign, double eps,
                              double g0, Eigen::MatrixXd* K, std::vector<Location>* locs) {
  const QuadratureRule rule = face_rule(sk, 3);
  const int m = 3 * (Xs.cols() + Xm.cols());
  Eigen::VectorXd r = Eigen::VectorXd::Zero(m);
  if (K) K->setZero(m, m);
  for (std::size_t q = 0; q < rule.xi.size(); ++q) {
    ShapeN N;
    shape(sk, rule.xi[q], N);
    const Projection p = project(mk, Xm, msign, Xs * N);
    if (locs) locs->push_back(p.location);
    Eigen::VectorXd rq;
    Eigen::MatrixXd Kq;
    surface_gp_kernel(sk, Xs, rule.xi[q], rule.w[q], mk, Xm, msign, p, eps, g0, rq, K ? &Kq : nullptr);
    r += rq;
    if (K) *K += Kq;
  }
  return r;
}

// A distorted quad slave over the master quad W, node a shifted by (0.01 a, -0.005 a, z0 + dz a).
FaceX distorted_slave(const FaceX& W, double z0, double dz) {
  FaceX S(3, 4);
  S.col(0) = evaluate(FaceKind::Quad4, W, Vec2(-0.5, -0.4)).x;
  S.col(1) = evaluate(FaceKind::Quad4, W, Vec2(-0.4, 0.5)).x;
  S.col(2) = evaluate(FaceKind::Quad4, W, Vec2(0.6, 0.4)).x;
  S.col(3) = evaluate(FaceKind::Quad4, W, Vec2(0.5, -0.5)).x;
  for (int a = 0; a < 4; ++a) S.col(a) += Vec3(0.01 * a, -0.005 * a, z0 + dz * a);
  return S;
}

void check_pair(FaceKind sk, const FaceX& Xs, FaceKind mk, const FaceX& Xm, double msign, double g0 = 0.0) {
  const double eps = 5.0;
  Eigen::MatrixXd K;
  std::vector<Location> locs;
  const Eigen::VectorXd r = pair_residual(sk, Xs, mk, Xm, msign, eps, g0, &K, &locs);
  ASSERT_GT(r.norm(), 0.0);
  const int ns = static_cast<int>(Xs.cols());
  Eigen::VectorXd u(r.size());
  u.head(3 * ns) = flatten(Xs);
  u.tail(r.size() - 3 * ns) = flatten(Xm);
  auto f = [&](const Eigen::VectorXd& v) {
    std::vector<Location> l2;
    const Eigen::VectorXd rr = pair_residual(sk, unflatten(v.head(3 * ns)), mk, unflatten(v.tail(v.size() - 3 * ns)),
                                             msign, eps, g0, nullptr, &l2);
    EXPECT_EQ(l2, locs);
    return rr;
  };
  const Eigen::MatrixXd Kfd = fd_jacobian(f, u, 1e-6);
  EXPECT_LT(rel_diff(K, Kfd), 1e-6) << name(sk) << "->" << name(mk);
  EXPECT_LT(rel_diff(K, K.transpose()), 1e-12);
  // force balance between the two sides (sum over all nodes of all forces = 0)
  Vec3 tot = Vec3::Zero();
  for (int a = 0; a < r.size() / 3; ++a) tot += r.segment<3>(3 * a);
  EXPECT_LT(tot.norm(), 1e-14 * (1 + r.norm()));
}
}  // namespace

// Compares against: central finite differences of the residual w.r.t. the nodal coordinates of BOTH faces
// (curved/warped slave and master, area variation included), its symmetry, and force balance.
TEST(SurfaceContact, TangentMatchesFiniteDifferences) {
  // master: warped quad, normal +-; slave: smaller distorted quad slightly below the master, facing it
  const FaceX W = warped_quad();
  const FaceX S = distorted_slave(W, -0.02, -0.01);  // below the master (+n side is up)
  check_pair(FaceKind::Quad4, S, FaceKind::Quad4, W, 1.0);
  // tri6 slave on a cylinder of radius 0.98 against a tri6 master of radius 1 seen from inside (normal -e_r)
  const FaceX Tm = cylinder_tri6(1.0);
  FaceX Ts = cylinder_tri6(1.015);  // penetrates the master (master normal points inward, slave is outside)
  for (int a = 3; a < 6; ++a) std::swap(Ts(0, a), Ts(0, a));
  Ts.col(5) += Vec3(0.004, -0.003, 0.002);
  check_pair(FaceKind::Tri6, Ts, FaceKind::Tri6, Tm, -1.0);
  // quad slave against tri3 master (mixed)
  FaceX T3(3, 3);
  T3.col(0) = Vec3(-1, -1, 0);
  T3.col(1) = Vec3(2, -1, 0.1);
  T3.col(2) = Vec3(-1, 2, -0.1);
  FaceX Q(3, 4);
  Q << 0, 0.5, 0.5, 0, 0, 0, 0.5, 0.5, -0.03, -0.02, -0.01, -0.04;
  check_pair(FaceKind::Quad4, Q, FaceKind::Tri3, T3, 1.0);
}

// Compares against: central finite differences (as above) with the C1 regularized law, the slave tilted so
// that its Gauss points lie on both sides of g = 0 (linear and quadratic branches of the law).
TEST(SurfaceContact, RegularizedTangentMatchesFiniteDifferences) {
  const FaceX W = warped_quad();
  const FaceX S = distorted_slave(W, 0.012, -0.012);  // gaps about +0.01 .. -0.025
  std::vector<double> gaps;
  const QuadratureRule rule = face_rule(FaceKind::Quad4, 3);
  for (const auto& xi : rule.xi) {
    ShapeN N;
    shape(FaceKind::Quad4, xi, N);
    gaps.push_back(project(FaceKind::Quad4, W, 1.0, S * N).d);
  }
  ASSERT_LT(*std::min_element(gaps.begin(), gaps.end()), 0.0);
  ASSERT_GT(*std::max_element(gaps.begin(), gaps.end()), 0.0);
  ASSERT_LT(*std::max_element(gaps.begin(), gaps.end()), 0.03);
  check_pair(FaceKind::Quad4, S, FaceKind::Quad4, W, 1.0, 0.03);
}

// Compares against: the closed form of the regularized law for two parallel flat patches apart by a gap
// 0 < g < g0: pressure eps (g0 - g)^2 / (2 g0) everywhere, total force that times the overlap area;
// at g >= g0 nothing is active.
TEST(SurfaceContact, RegularizedParallelPatchesExactPressure) {
  const double eps = 5.0, g0 = 0.04, gap = 0.01;
  TwoPatches t = two_patches(0.5, 1.5, 0.3, 1.7, 3, 5, -gap);
  SurfaceContactParams par;
  par.penalty = eps;
  par.regularization = g0;
  const SurfaceContactResult r = patches_contact(t, par);
  const double p = eps * (g0 - gap) * (g0 - gap) / (2.0 * g0), area = 1.0 * 1.4;
  EXPECT_EQ(r.diag.num_active, 15 * 4);
  for (const auto& gp : r.points) EXPECT_NEAR(gp.pressure, p, 1e-14);
  EXPECT_NEAR(r.diag.force_on_solid.z(), -p * area, 1e-13);
  par.regularization = 0.5 * gap;
  EXPECT_EQ(patches_contact(t, par).diag.num_active, 0);
}

// Compares against: the analytic penetration of a balloon-like tube (slave, outer radius 1.02) inside an
// artery-like tube (master, radius 1.0, normal into the lumen): all Gauss points active with g ~ -0.02 and a
// net force ~0 by symmetry.
TEST(SurfaceContact, ConcentricTubes) {
  Mesh art = cylinder(FaceKind::Quad4, 1.0, 1.0, 48, 4);
  Mesh bal = cylinder(FaceKind::Quad4, 1.02, 1.0, 40, 5);
  art.surface.normal_sign = -1.0;
  Mesh all = art;
  const int off = static_cast<int>(all.x.size());
  all.x.insert(all.x.end(), bal.x.begin(), bal.x.end());
  Surface slave = bal.surface;
  for (Face& f : slave.faces)
    for (int a = 0; a < 4; ++a) f.nodes[a] += off;
  SurfaceSearch Ss(slave, 0.1), Sm(art.surface, 0.1);
  Ss.update(all.x);
  Sm.update(all.x);
  const SurfaceContactResult r = evaluate_surface_contact(Ss, Sm, SurfaceContactParams{});
  EXPECT_EQ(r.diag.num_active, 200 * 4);
  EXPECT_NEAR(r.diag.min_gap, -0.02, 2.5e-3);
  EXPECT_LT(r.diag.force_on_solid.norm(), 1e-10);
  EXPECT_GT(r.diag.force_magnitude, 0.0);
}

// Compares against: central finite differences of the globally assembled residual for a curved quad4 slave tube
// section pressed into a tri6 master tube section (all nodes of both perturbed, projections re-searched).
TEST(SurfaceContact, AssembledTangentMatchesFiniteDifferences) {
  Mesh mas = cylinder(FaceKind::Tri6, 1.0, 0.6, 3, 1, 0.0, 0.6);
  Mesh sla = cylinder(FaceKind::Quad4, 1.01, 0.4, 2, 2, 0.1, 0.5);
  mas.surface.normal_sign = -1.0;                                       // master normal into the lumen
  for (Face& f : sla.surface.faces) std::swap(f.nodes[1], f.nodes[3]);  // slave normal outward -> flip to face master
  Mesh all = mas;
  const int off = static_cast<int>(all.x.size());
  for (const Vec3& p : sla.x) all.x.push_back(p + Vec3(0, 0, 0.1));
  Surface slave = sla.surface;
  for (Face& f : slave.faces)
    for (int a = 0; a < 4; ++a) f.nodes[a] += off;
  const int n = static_cast<int>(all.x.size());
  double energy = 0;
  auto assemble = [&](const Eigen::VectorXd& u, Eigen::MatrixXd* K) {
    std::vector<Vec3> x(n);
    for (int i = 0; i < n; ++i) x[i] = u.segment<3>(3 * i);
    SurfaceSearch Ss(slave, 0.1), Sm(mas.surface, 0.1);
    Ss.update(x);
    Sm.update(x);
    SurfaceContactParams par;
    par.compute_tangent = K != nullptr;
    const SurfaceContactResult res = evaluate_surface_contact(Ss, Sm, par);
    energy = res.diag.energy;
    return assemble_dense(res.contributions, n, K);
  };
  Eigen::VectorXd u(3 * n);
  for (int i = 0; i < n; ++i) u.segment<3>(3 * i) = all.x[i];
  // tangent = FD Jacobian; the residual is the gradient of the penalty potential Pi = sum W eps/2 <g_N>^2 (current area
  // W)
  Eigen::VectorXd r;
  expect_fd_consistent(assemble, energy, u, r);
  Vec3 tot = Vec3::Zero();
  for (int i = 0; i < n; ++i) tot += r.segment<3>(3 * i);
  EXPECT_LT(tot.norm(), 1e-13 * r.norm());
}
