// Contact wired into the solid solver (solid_solver/src/stent_contact.cpp, contact_scene.cpp).
// Run under mpirun with 1 and 2 ranks.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petsc/private/petscimpl.h>
#include <petscsys.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <iomanip>
#include <random>
#include <sstream>

#include "angio/scene/node.hpp"
#include "angio/solid/contact_scene.hpp"
#include "angio/solid/model.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/petsc_options_check.hpp"
#include "angio/solid/scene.hpp"
#include "angio/solid/stent_contact.hpp"
#include "mpi_test.hpp"

using namespace angio::solid;
namespace participant = angio::participant;

using angio_test::world_rank;
using angio_test::world_size;

namespace {

Mesh tube(const std::string& part, double inner_radius, double wall, double length, int n_circ, int n_axial,
          int n_radial = 1) {
  TubeSpec t;
  t.part = part;
  t.surface_prefix = part + "_";
  t.length = length;
  t.inner_radius = inner_radius;
  t.layers = {{part, wall, n_radial}};
  t.n_circ = n_circ;
  t.n_axial = n_axial;
  return make_tube(t);
}

ModelOptions tight_options() {
  ModelOptions o;
  o.petsc_options = "-ksp_rtol 1e-13 -ksp_atol 1e-16";
  o.newton.rtol = 1e-11;
  o.newton.atol = 1e-12;
  return o;
}

LayerMaterial neo_hooke(const std::string& name, double E, double nu) { return LayerMaterial{name, {E, nu}, {}}; }

// Sum of a distributed vector per component (dofs are interlaced: global dof % 3 = component).
std::array<double, 3> component_sums(Vec v) {
  PetscInt lo, hi;
  VecGetOwnershipRange(v, &lo, &hi);
  const PetscScalar* a;
  VecGetArrayRead(v, &a);
  std::array<double, 3> loc{0, 0, 0}, glob{};
  for (PetscInt i = lo; i < hi; ++i) loc[i % 3] += a[i - lo];
  VecRestoreArrayRead(v, &a);
  MPI_Allreduce(loc.data(), glob.data(), 3, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  return glob;
}

// Whole vector on every rank (global dof order).
std::vector<double> gather_all(Vec v) {
  VecScatter sc;
  Vec all;
  VecScatterCreateToAll(v, &sc, &all);
  VecScatterBegin(sc, v, all, INSERT_VALUES, SCATTER_FORWARD);
  VecScatterEnd(sc, v, all, INSERT_VALUES, SCATTER_FORWARD);
  PetscInt n;
  VecGetSize(all, &n);
  const PetscScalar* a;
  VecGetArrayRead(all, &a);
  std::vector<double> out(a, a + n);
  VecRestoreArrayRead(all, &a);
  VecScatterDestroy(&sc);
  VecDestroy(&all);
  return out;
}

// A point at distance (R - depth) from the centre of face f along its outward normal: penetration `depth`.
participant::Vec3 pressed_point(const Mesh& m, const Face& f, double R, double depth, Vec3d* normal = nullptr) {
  Vec3d c = Vec3d::Zero();
  for (int a = 0; a < 4; ++a) c += m.X[f.n[a]] / 4.0;
  Vec3d n = (m.X[f.n[2]] - m.X[f.n[0]]).cross(m.X[f.n[3]] - m.X[f.n[1]]).normalized();
  if (normal) *normal = n;
  const Vec3d x = c + (R - depth) * n;
  return {x(0), x(1), x(2)};
}

}  // namespace

// (1) One beam point pressed into a balloon-like tube, through SolidModel::assemble (the model's own r and K):
// compared with (a) the reply's line loads: applied force on the solid (-sum r) = -sum w q (global force
// balance, round-off), and (b) the closed form eps * penetration * w for a point over the centre of a flat
// (planar) quad face with the normal along the face normal.
TEST(StentContact, SinglePointForceBalance) {
  Mesh m = tube("balloon", 0.45, 0.04, 2.0, 16, 6);
  const Face f = m.surface("balloon_outer")->faces[37];
  const double R = 0.06, depth = 0.004, w = 0.05, eps = 10.0;
  Vec3d n;
  participant::SamplePoints pts;
  pts.x = {pressed_point(m, f, R, depth, &n)};
  pts.w = {w};
  pts.radius = {R};
  SolidModel model(PETSC_COMM_WORLD, m, {neo_hooke("balloon", 17.0, 0.0)}, tight_options());
  PenaltyStentContact::Options o;
  o.balloon_penalty = eps;
  PenaltyStentContact contact(model, o);
  ASSERT_EQ(contact.num_surfaces(), 1);
  model.set_contact(&contact);
  contact.set_points(pts);
  ASSERT_TRUE(model.assemble(model.residual_vector(), model.matrix()));  // u = 0: only contact contributes
  const auto rsum = component_sums(model.residual_vector());
  participant::ContactReply reply;
  reset_reply(pts, reply);
  contact.fill_reply(model, reply);
  if (world_rank() == 0) {  // the reply is rank 0's (the rank that answers the coupler)
    EXPECT_EQ(reply.n_active, 1);
    EXPECT_EQ(reply.active[0], 1);
    EXPECT_NEAR(reply.min_gap, -depth, 1e-12);
    EXPECT_DOUBLE_EQ(reply.penalty[0], eps);
    for (int c = 0; c < 3; ++c) {
      // force on the solid = -sum r = -sum w q  <=>  sum r = sum w q
      EXPECT_NEAR(rsum[c], reply.total_force[c], 1e-14) << c;
      EXPECT_NEAR(reply.total_force[c], eps * depth * w * n(c), 1e-12) << c;
      EXPECT_NEAR(reply.line_loads[0][c], eps * depth * n(c), 1e-10) << c;
      EXPECT_NEAR(reply.normals[0][c], n(c), 1e-10) << c;
    }
  }
  EXPECT_EQ(contact.last().num_active, 1);
  EXPECT_NEAR(contact.last().min_gap, -depth, 1e-12);
  EXPECT_NEAR(contact.last().force, eps * depth * w, 1e-12);
}

// (1b) The same through SolidRunner and the scene's contact: section: a ring of beam points pressing the balloon
// inward is solved to equilibrium; at the converged state the contact residual (added into a fresh vector)
// balances the reply's sum w q (force balance), and the balloon moves inward under the points.
// A balloon tube (16 x 8 hex8) with stent-balloon contact; `contact_keys`: further keys of contact:.
std::string ring_scene(const std::string& contact_keys) {
  return R"(
time: {end: 1.0, steps: 1}
balloon:
  mesh: {generator: tube, length: 2.0, outer_diameter: 0.98, wall: 0.04, n_circ: 16, n_axial: 8}
  material: {E: 17.0, nu: 0.0}
  end_springs: 1.0e3
contact:
  stent_balloon: {penalty: 10.0}
  search_radius: 0.3
  log: false
)" + contact_keys +
         R"(
solid:
  petsc_options: "-ksp_rtol 1e-12"
  newton: {rtol: 1.0e-10, atol: 1.0e-12}
)";
}

// 24 beam points on a ring 0.03 mm inside the balloon's nodal radius, at z = 0.13 mm + wobble sin(3a).
participant::SamplePoints ring_points(double wobble) {
  participant::SamplePoints pts;
  const double R = 0.06, r_beam = 0.49 + R - 0.03;
  for (int i = 0; i < 24; ++i) {
    const double a = 2 * M_PI * (i + 0.3) / 24;
    pts.x.push_back({r_beam * std::cos(a), r_beam * std::sin(a), 0.13 + wobble * std::sin(3.0 * a)});
    pts.w.push_back(0.1);
    pts.radius.push_back(R);
  }
  return pts;
}

TEST(StentContact, RunnerRingOfPointsConverges) {
  const angio::scene::Node root(YAML::Load(ring_scene("")), "inline.yaml", "");
  SolidRunner runner(PETSC_COMM_WORLD, read_solid_scene(root), "");
  auto setup = make_contact(root, runner);
  ASSERT_NE(setup->stent(), nullptr);
  EXPECT_EQ(setup->balloon_artery(), nullptr);
  const participant::SamplePoints pts = ring_points(0.0);
  participant::ContactReply reply;
  runner.begin_step(1, 1.0);
  const auto st = runner.solve(pts, reply, 0.0);
  ASSERT_TRUE(st.converged) << st.message;
  if (world_rank() == 0) {  // the reply is rank 0's
    EXPECT_EQ(reply.n_active, 24);
    EXPECT_LT(reply.min_gap, 0.0);
    EXPECT_GT(reply.min_gap, -0.03);  // the balloon gave way
    double qn = 0;
    for (const auto& q : reply.line_loads) qn += std::hypot(q[0], q[1]);
    EXPECT_GT(qn, 0.0);
  }
  Vec r;
  VecDuplicate(runner.model().residual_vector(), &r);
  VecSet(r, 0.0);
  setup->stent()->add(runner.model(), r, nullptr);
  VecAssemblyBegin(r);
  VecAssemblyEnd(r);
  const auto rs = component_sums(r);
  if (world_rank() == 0) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rs[c], reply.total_force[c], 1e-13) << c;
  }
  VecDestroy(&r);
  // The reply took the converged Newton's last evaluation of each rank's slice: the contact of the final
  // configuration, bit for bit a fresh evaluation's.
  participant::ContactReply fresh;
  reset_reply(pts, fresh);
  setup->stent()->set_points(pts);  // drops any kept evaluation
  setup->stent()->fill_reply(runner.model(), fresh);
  EXPECT_EQ(fresh.line_loads, reply.line_loads);
  EXPECT_EQ(fresh.surface_points, reply.surface_points);
  EXPECT_EQ(fresh.normals, reply.normals);
  EXPECT_EQ(fresh.penalty, reply.penalty);
  EXPECT_EQ(fresh.n_active, reply.n_active);
  runner.end_step(true);
}

// (1c) Consistency of contact.line_tangent: the face tangent (default) leaves out columns of the averaged
// normals' exact tangent but not of the residual, so a Newton with it converges to the state of a Newton
// with the exact (ring) tangent: the same ring of points pressing the balloon gives the same line loads to
// the Newton tolerance, the face tangent in no fewer iterations (it is not exact); so do the gap tangent,
// which also leaves out the terms of the force's magnitude, and the definite tangent, which keeps their
// positive semidefinite part.
TEST(StentContact, FaceTangentConvergesToTheRingTangentsState) {
  auto solve = [](const char* tangent, int& iterations) {
    const std::string keys = std::string("  line_normals: averaged\n  line_tangent: ") + tangent + "\n";
    const angio::scene::Node root(YAML::Load(ring_scene(keys)), "inline.yaml", "");
    SolidRunner runner(PETSC_COMM_WORLD, read_solid_scene(root), "");
    auto setup = make_contact(root, runner);
    const participant::SamplePoints pts = ring_points(0.01);
    participant::ContactReply reply;
    runner.begin_step(1, 1.0);
    const auto st = runner.solve(pts, reply, 0.0);
    EXPECT_TRUE(st.converged) << tangent << ": " << st.message;
    if (world_rank() == 0) {
      EXPECT_EQ(reply.n_active, 24) << tangent;  // the reply is rank 0's
    }
    iterations = st.iterations;
    runner.end_step(true);
    return reply.line_loads;
  };
  int it_ring = 0;
  const auto ring = solve("ring", it_ring);
  // gap: also without the force's terms; definite: with their positive semidefinite part only
  for (const char* other : {"face", "gap", "definite"}) {
    int it = 0;
    const auto loads = solve(other, it);
    ASSERT_EQ(ring.size(), loads.size());
    EXPECT_GE(it, it_ring) << other;
    if (world_rank() != 0) continue;  // the line loads are rank 0's
    double diff = 0, scale = 0;
    for (size_t i = 0; i < ring.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        diff = std::max(diff, std::abs(ring[i][c] - loads[i][c]));
        scale = std::max(scale, std::abs(ring[i][c]));
      }
    EXPECT_GT(scale, 0.0);
    EXPECT_LT(diff, 1e-8 * scale) << other;
  }
}

// Three stent points (radius 0.06 mm) pressed 5 um into faces 3, 14 and 22 of the balloon's outer surface.
participant::SamplePoints pressed_into_balloon(const Mesh& m) {
  participant::SamplePoints pts;
  const auto& faces = m.surface("balloon_outer")->faces;
  for (int k : {3, 14, 22}) {
    pts.x.push_back(pressed_point(m, faces[k], 0.06, 0.005));
    pts.w.push_back(0.07);
    pts.radius.push_back(0.06);
  }
  return pts;
}

// (2) The assembled tangent of the model (elements + stent line contact + balloon-artery surface contact, through
// ContactModel::add into the model's PETSc Mat, including the new balloon-artery couplings) compared with
// central finite differences of the assembled residual; with closest-point and with averaged normals (the latter
// couples each face with the ring of nodes around it, whose rows may belong to the other rank).
void check_model_tangent(bool averaged_normals) {
  Mesh m = tube("balloon", 0.44, 0.04, 1.2, 10, 3);
  m.append(tube("artery", 0.47, 0.1, 1.6, 8, 3));  // balloon outer radius 0.48 > artery inner radius 0.47
  SolidModel model(PETSC_COMM_WORLD, m, {neo_hooke("balloon", 1.0, 0.3), neo_hooke("artery", 0.5, 0.3)},
                   tight_options());
  const participant::SamplePoints pts = pressed_into_balloon(model.mesh());
  PenaltyStentContact::Options so;
  so.balloon_penalty = 10.0;
  so.artery_penalty = 8.0;
  so.averaged_normals = averaged_normals;
  so.ring_tangent = true;  // the exact tangent
  PenaltyStentContact stent(model, so);
  PenaltySurfaceContact::Options bo;
  bo.penalty = 5.0;
  PenaltySurfaceContact ba(model, bo);
  CompositeContact comp;
  comp.set_stent(&stent);
  comp.add_model(&ba);
  model.set_contact(&comp);
  comp.set_points(pts);
  // a small generic displacement state (same on all ranks)
  const int nn = int(model.mesh().X.size());
  std::vector<Vec3d> u0(nn);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1e-3, 1e-3);
  for (auto& v : u0) v = Vec3d(U(rng), U(rng), U(rng));
  model.set_displacement(u0);
  ASSERT_TRUE(model.assemble(model.residual_vector(), model.matrix()));
  EXPECT_GT(stent.last().num_active, 3);  // points touch balloon and artery
  EXPECT_GT(ba.last().num_active, 0);
  Mat K = model.matrix();
  PetscInt lo, hi;
  MatGetOwnershipRange(K, &lo, &hi);
  Vec r;
  VecDuplicate(model.residual_vector(), &r);
  const double h = 1e-6;
  double max_err = 0, max_k = 0, max_cross = 0;
  std::vector<PetscInt> rows;
  for (PetscInt i = lo; i < hi; ++i) rows.push_back(i);
  std::vector<double> kcol(rows.size());
  for (int j = 0; j < 3 * nn; ++j) {
    const int node = model.old_index(j / 3), c = j % 3;
    std::vector<Vec3d> up = u0, um = u0;
    up[node](c) += h;
    um[node](c) -= h;
    model.set_displacement(up);
    model.assemble(r, nullptr);
    const auto rp = gather_all(r);
    model.set_displacement(um);
    model.assemble(r, nullptr);
    const auto rm = gather_all(r);
    PetscInt col = j;
    if (!rows.empty()) MatGetValues(K, PetscInt(rows.size()), rows.data(), 1, &col, kcol.data());
    for (size_t a = 0; a < rows.size(); ++a) {
      const double fd = (rp[rows[a]] - rm[rows[a]]) / (2 * h);
      max_err = std::max(max_err, std::abs(fd - kcol[a]));
      max_k = std::max(max_k, std::abs(kcol[a]));
    }
  }
  // cross-body coupling entries must exist: balloon nodes come first in the appended mesh
  const int nb = int(tube("balloon", 0.44, 0.04, 1.2, 10, 3).X.size());
  for (size_t a = 0; a < rows.size(); ++a) {
    const bool row_balloon = model.old_index(int(rows[a] / 3)) < nb;
    for (int j = 0; j < 3 * nn; ++j) {
      const bool col_balloon = model.old_index(j / 3) < nb;
      if (row_balloon == col_balloon) continue;
      PetscInt col = j, row = rows[a];
      double v = 0;
      MatGetValues(K, 1, &row, 1, &col, &v);
      max_cross = std::max(max_cross, std::abs(v));
    }
  }
  double g[3] = {max_err, max_k, max_cross}, gg[3];
  MPI_Allreduce(g, gg, 3, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  if (world_rank() == 0)
    std::printf("  tangent: max |K - K_fd| = %.3e, max |K| = %.3e, max |K_cross| = %.3e\n", gg[0], gg[1], gg[2]);
  EXPECT_LT(gg[0], 1e-6 * gg[1]);
  EXPECT_GT(gg[2], 1e-3 * gg[1]);
  VecDestroy(&r);
}

TEST(StentContact, TangentMatchesFiniteDifferences) { check_model_tangent(false); }
TEST(StentContact, TangentMatchesFiniteDifferencesAveragedNormals) { check_model_tangent(true); }

// (3) The couplings of the averaged normals' rings are part of the matrix's pattern before the first
// contact assembly: inserting the tangent of active points allocates nothing (a PETSc AIJ matrix copies
// itself for every entry outside its pattern). Consistency property of the assembly, on 1 and 2 ranks:
// without PenaltyStentContact::couplings() the rings (4 x 4 surface nodes around a quad4 face) reach
// past the hex8 elements' pattern and the count is positive.
// With the face tangent (contact.line_tangent: face, the default) nothing is declared and nothing is
// allocated either: the matrix holds exactly the elements' entries, as without contact.
void check_averaged_pattern(bool ring) {
  Mesh m = tube("balloon", 0.44, 0.04, 1.2, 10, 3);
  SolidModel model(PETSC_COMM_WORLD, m, {neo_hooke("balloon", 1.0, 0.3)}, tight_options());
  MatInfo bare;
  MatGetInfo(model.matrix(), MAT_GLOBAL_SUM, &bare);
  const participant::SamplePoints pts = pressed_into_balloon(model.mesh());
  PenaltyStentContact::Options so;
  so.balloon_penalty = 10.0;
  so.averaged_normals = true;
  so.ring_tangent = ring;
  PenaltyStentContact stent(model, so);
  model.set_contact(&stent);
  stent.set_points(pts);
  ASSERT_TRUE(model.assemble(model.residual_vector(), model.matrix()));
  EXPECT_EQ(stent.last().num_active, 3);
  MatInfo info;
  MatGetInfo(model.matrix(), MAT_GLOBAL_SUM, &info);
  EXPECT_EQ(info.mallocs, 0.0);
  if (ring)
    EXPECT_GT(info.nz_allocated, bare.nz_allocated);
  else
    EXPECT_EQ(info.nz_allocated, bare.nz_allocated);
}

TEST(StentContact, AveragedNormalsTangentFitsThePattern) { check_averaged_pattern(true); }
TEST(StentContact, AveragedNormalsFaceTangentKeepsTheElementsPattern) { check_averaged_pattern(false); }

// Cost of the stent contact in an assembly (printed): 1260 sample points (4-ring stent: 210 elements x 6) on a
// helix pressing 2 um into the paper's balloon (22 x 58 hex8); compared with the whole assembly (elements +
// contact) of the same model. No physical reference; checks that every point is active and the forces balance.
TEST(StentContact, CostOfManyPoints) {
  Mesh m = tube("balloon", 0.45, 0.04, 9.4, 22, 58);
  SolidModel model(PETSC_COMM_WORLD, m, {neo_hooke("balloon", 17.0, 0.0)}, tight_options());
  PenaltyStentContact::Options o;
  o.balloon_penalty = 10.0;
  PenaltyStentContact contact(model, o);
  model.set_contact(&contact);
  participant::SamplePoints pts;
  const int n = 1260;
  const double R = 0.06, rb = 0.49 * std::cos(M_PI / 22) + R - 0.002;  // 2 um into the facets
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * 7.3 * i / n, z = -3.0 + 6.0 * i / n;
    pts.x.push_back({rb * std::cos(a), rb * std::sin(a), z});
    pts.w.push_back(0.02);
    pts.radius.push_back(R);
  }
  contact.set_points(pts);
  const int reps = 3;
  const double t0 = MPI_Wtime();
  for (int k = 0; k < reps; ++k) ASSERT_TRUE(model.assemble(model.residual_vector(), model.matrix()));
  const double t_asm = (MPI_Wtime() - t0) / reps;
  const double t_contact = contact.timing().seconds / double(contact.timing().calls);
  if (world_rank() == 0)
    std::printf(
        "  %d points: contact add() %.2f ms per assembly (search + evaluation + insertion), whole assembly "
        "%.2f ms (%.0f %%); %d active\n",
        n, 1e3 * t_contact, 1e3 * t_asm, 100.0 * t_contact / t_asm, contact.last().num_active);
  EXPECT_EQ(contact.last().num_active, n);
  participant::ContactReply reply;
  reset_reply(pts, reply);
  contact.fill_reply(model, reply);
  const auto rsum = component_sums(model.residual_vector());
  if (world_rank() == 0) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rsum[c], reply.total_force[c], 1e-12) << c;
  }
}

// (2b) The reply is gathered on rank 0 from each rank's slice of the points: on 2 ranks it is bit for bit the
// reply of the same contact evaluated whole on one rank (consistency, 1 vs N ranks), both from the assembly's
// evaluation (a converged Newton's last) and from a fresh one; so are the gaps. Points pressing in, clear of
// the surface, and beyond the search radius (no plane), with averaged normals (their projection's hints).
TEST(StentContact, ReplyOnRankZeroIsTheWholeEvaluation) {
  const Mesh m = tube("balloon", 0.45, 0.04, 4.0, 22, 24);
  participant::SamplePoints pts;
  const int n = 301;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * 3.1 * i / n, z = -2.6 + 5.2 * i / n;  // |z| > 2: beyond the tube's ends
    const double rb = 0.49 + 0.06 + 0.02 * std::sin(5.0 * a);         // up to 20 um in and out
    pts.x.push_back({rb * std::cos(a), rb * std::sin(a), z});
    pts.w.push_back(0.02);
    pts.radius.push_back(0.06);
  }
  PenaltyStentContact::Options o;
  o.balloon_penalty = 10.0;
  o.averaged_normals = true;
  o.search_radius = 0.2;
  auto reply_and_gaps = [&](MPI_Comm comm, std::vector<participant::ContactReply>& replies, std::vector<double>& gap) {
    SolidModel model(comm, m, {neo_hooke("balloon", 17.0, 0.0)}, tight_options());
    PenaltyStentContact contact(model, o);
    model.set_contact(&contact);
    contact.set_points(pts);
    ASSERT_TRUE(model.assemble(model.residual_vector(), model.matrix()));
    replies.assign(2, {});
    reset_reply(pts, replies[0]);
    contact.fill_reply(model, replies[0]);  // the assembly's evaluation
    contact.set_points(pts);
    reset_reply(pts, replies[1]);
    contact.fill_reply(model, replies[1]);  // a fresh one
    std::vector<double> weight;
    contact.gaps(model, "balloon_outer", gap, weight);
  };
  std::vector<participant::ContactReply> ranks;
  std::vector<double> gap_ranks;
  reply_and_gaps(PETSC_COMM_WORLD, ranks, gap_ranks);
  if (world_rank() != 0) {
    EXPECT_TRUE(gap_ranks.empty());
    return;
  }
  std::vector<participant::ContactReply> one;
  std::vector<double> gap_one;
  reply_and_gaps(PETSC_COMM_SELF, one, gap_one);
  int active = 0, planes = 0;
  for (std::size_t i = 0; i < pts.x.size(); ++i) planes += one[0].penalty[i] > 0.0;
  for (int a : one[0].active) active += a;
  EXPECT_GT(active, 50);  // every kind of point is there
  EXPECT_GT(planes - active, 50);
  EXPECT_GT(n - planes, 30);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(ranks[k].line_loads, one[k].line_loads) << k;
    EXPECT_EQ(ranks[k].surface_points, one[k].surface_points) << k;
    EXPECT_EQ(ranks[k].normals, one[k].normals) << k;
    EXPECT_EQ(ranks[k].penalty, one[k].penalty) << k;
    EXPECT_EQ(ranks[k].active, one[k].active) << k;
    EXPECT_EQ(ranks[k].n_active, one[k].n_active) << k;
    EXPECT_EQ(ranks[k].min_gap, one[k].min_gap) << k;
    EXPECT_EQ(ranks[k].total_force, one[k].total_force) << k;  // summed in point order on rank 0
  }
  EXPECT_EQ(gap_ranks, gap_one);
}

// (3) Balloon-artery: a pressurized inner tube presses on an outer tube (non-matching meshes). The load steps
// converge, the tubes come into contact, and max displacement / contact force are the same on 1 and on 2 MPI
// ranks (on 2 ranks, rank 0 also solves the same problem alone on PETSC_COMM_SELF and compares).
namespace {
struct BAResult {
  bool converged = true;
  double max_u = 0, force = 0, force_magnitude = 0, min_gap = 0, area = 0;
  int active = 0;
  std::vector<std::string> unused;  // petsc options no solver object asked for
  double mallocs = 0;               // of the matrix during insertion, summed over the steps
  int pattern_rebuilds = 0;
  int rebuilds_before_contact = -1;  // pattern rebuilds after a tangent assembly at the start, nothing touching
  std::string failure;               // the step, the solver's message and residuals of a solve that did not converge
  int newton_iterations = 0, factorizations = 0;
  // with -pc_type fieldsplit: per step, each LU split's factored matrix (object, state) after the solve
  std::vector<std::vector<std::pair<Mat, PetscObjectState>>> split_factors;
};
std::vector<std::pair<Mat, PetscObjectState>> split_factors(const SolidModel& model) {
  PC pc;
  KSPGetPC(model.linear_solver(), &pc);
  PetscBool split = PETSC_FALSE;
  PetscObjectTypeCompare((PetscObject)pc, PCFIELDSPLIT, &split);
  std::vector<std::pair<Mat, PetscObjectState>> out;
  if (!split) return out;
  PetscInt n = 0;
  KSP* sub = nullptr;
  PCFieldSplitGetSubKSP(pc, &n, &sub);
  for (PetscInt k = 0; k < n; ++k) {
    PC spc;
    KSPGetPC(sub[k], &spc);
    Mat f = nullptr;
    PetscObjectState state = 0;
    PetscBool lu = PETSC_FALSE;
    PetscObjectTypeCompare((PetscObject)spc, PCLU, &lu);
    if (lu) PCFactorGetMatrix(spc, &f);
    if (f) state = ((PetscObject)f)->state;  // raised by every numeric factorization (no public getter in 3.18)
    out.emplace_back(f, state);
  }
  PetscFree(sub);
  return out;
}
BAResult balloon_artery_run(MPI_Comm comm, const std::string& petsc_options = "",
                            const std::function<void(NewtonOptions&)>& newton = nullptr) {
  Mesh m = tube("balloon", 0.46, 0.04, 2.0, 16, 8);
  m.append(tube("artery", 0.55, 0.2, 2.6, 12, 7));
  ModelOptions o = tight_options();
  o.petsc_options += " " + petsc_options;
  o.newton.rtol = 1e-10;
  o.newton.atol = 1e-11;
  if (newton) newton(o.newton);
  SolidModel model(comm, m, {neo_hooke("balloon", 1.0, 0.3), neo_hooke("artery", 0.1, 0.3)}, o);
  model.add_pressure({"balloon_inner", [](double t) { return 0.03 * t; }});
  for (const char* s : {"balloon_end0", "balloon_end1", "artery_end0", "artery_end1"}) model.add_springs({s, 10.0});
  PenaltySurfaceContact::Options bo;
  bo.penalty = 50.0;
  bo.search_radius = 0.2;
  PenaltySurfaceContact ba(model, bo);
  model.set_contact(&ba);
  BAResult res;
  model.set_time(0.0);  // the balloon 0.05 mm from the artery, within the search radius: pairs, none active
  model.assemble(model.residual_vector(), model.matrix());
  if (ba.last().num_active == 0 && ba.last().min_gap < bo.search_radius)
    res.rebuilds_before_contact = model.pattern_rebuilds();
  for (int step = 1; step <= 4; ++step) {
    model.set_time(0.25 * step);
    const auto rep = model.solve();
    if (!rep.converged) {
      res.converged = false;
      std::ostringstream m;  // scientific: the residuals span 1e-2 .. 1e-16
      m << "step " << step << ": " << rep.message << "; |r| history:" << std::scientific << std::setprecision(3);
      for (double r : rep.residual_history) m << " " << r;
      res.failure = m.str();
      return res;
    }
    res.newton_iterations += rep.iterations;
    res.factorizations += rep.factorizations;
    res.split_factors.push_back(split_factors(model));
    model.commit();
    MatInfo info;  // since the matrix was last (re)built: every assembly of the step after its last rebuild
    MatGetInfo(model.matrix(), MAT_GLOBAL_SUM, &info);
    res.mallocs += info.mallocs;
  }
  res.pattern_rebuilds = model.pattern_rebuilds();
  for (const Vec3d& u : model.gather_displacement()) res.max_u = std::max(res.max_u, u.norm());
  res.force = ba.last().force;
  res.force_magnitude = ba.last().force_magnitude;
  res.min_gap = ba.last().min_gap;
  res.active = ba.last().num_active;
  res.area = ba.active_area();
  res.unused = model.unused_petsc_options();
  return res;
}
}  // namespace

TEST(BalloonArtery, ConvergesAndMatchesOnOneAndTwoRanks) {
  const BAResult a = balloon_artery_run(PETSC_COMM_WORLD);
  ASSERT_TRUE(a.converged) << a.failure;
  if (world_rank() == 0)
    std::printf(
        "  balloon-artery (%d ranks): max|u| = %.9f mm, active %d, min gap %.3e mm, sum|f| = %.9f N, area %.4f\n",
        world_size(), a.max_u, a.active, a.min_gap, a.force_magnitude, a.area);
  EXPECT_GT(a.active, 0);
  EXPECT_LT(a.min_gap, 0.0);
  EXPECT_GT(a.max_u, 0.05);                              // the 0.05 mm radial gap closed
  EXPECT_LT(a.force, 1e-6 * a.force_magnitude + 1e-12);  // axisymmetric: net force on the artery ~ 0
  // The pairs' couplings enter the matrix's pattern before their entries are inserted (when a new pair
  // touches, with every pair within the search radius that the pattern lacks: ContactModel::prepare):
  // no assembly reallocates the matrix. Without prepare() the count is positive (6,264 on 1 rank, 2,820
  // on 2, measured). While nothing touches, the matrix is not rebuilt (a tangent assembly at the start,
  // the balloon 0.05 mm inside the 0.2 mm search radius: one rebuild when pairs entered on coming
  // within the radius).
  EXPECT_EQ(a.mallocs, 0.0);
  EXPECT_GT(a.pattern_rebuilds, 0);
  EXPECT_EQ(a.rebuilds_before_contact, 0);
  if (world_size() > 1) {
    BAResult b;
    if (world_rank() == 0) b = balloon_artery_run(PETSC_COMM_SELF);
    double v[4] = {b.max_u, b.force_magnitude, b.min_gap, double(b.active)};
    MPI_Bcast(v, 4, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    if (world_rank() == 0) std::printf("  balloon-artery (1 rank): max|u| = %.9f mm, sum|f| = %.9f N\n", v[0], v[1]);
    EXPECT_NEAR(a.max_u, v[0], 1e-7 * v[0]);
    EXPECT_NEAR(a.force_magnitude, v[1], 1e-6 * v[1]);
    EXPECT_NEAR(a.min_gap, v[2], 1e-6 * std::abs(v[2]));
    EXPECT_EQ(a.active, int(v[3]));
  }
}

// FGMRES around a block Gauss-Seidel of the two bodies, the balloon's split by LU (the artery's: per test)
const std::string by_parts =
    "-ksp_type fgmres -ksp_gmres_restart 100 -pc_type fieldsplit -pc_fieldsplit_type multiplicative "
    "-fieldsplit_balloon_ksp_type preonly -fieldsplit_balloon_pc_type lu ";

// -pc_type fieldsplit: one split per part, named after it (the balloon by LU, the artery by GMRES
// with GAMG and its rigid-body modes), the two coupled through the contact by FGMRES. Consistency
// property: the same converged state as the default solver's; and the options check knows the splits'
// names. The artery's split is solved to 1e-10, not by one V-cycle: with one V-cycle the outer GMRES
// needed up to its 1,000 iterations for the tight -ksp_rtol 1e-13 and, on 2 ranks, broke down in about
// one run of six (measured); solved, the outer FGMRES needs at most ~150 (12 runs).
TEST(BalloonArtery, SplitsByPartGiveTheSameState) {
  const BAResult a = balloon_artery_run(PETSC_COMM_WORLD);
  const std::string split =
      by_parts + "-fieldsplit_artery_ksp_type gmres -fieldsplit_artery_ksp_rtol 1e-10 -fieldsplit_artery_pc_type gamg";
  const BAResult b = balloon_artery_run(PETSC_COMM_WORLD, split);
  ASSERT_TRUE(a.converged) << a.failure;
  ASSERT_TRUE(b.converged) << b.failure;
  EXPECT_NEAR(b.max_u, a.max_u, 1e-7 * a.max_u);
  EXPECT_NEAR(b.force_magnitude, a.force_magnitude, 1e-6 * a.force_magnitude);
  EXPECT_EQ(b.active, a.active);
  EXPECT_TRUE(b.unused.empty()) << b.unused.front();  // each split's options reached its solver
  const auto ok = check_petsc_options(split, {"balloon", "artery"});
  EXPECT_EQ(ok.error, "");
  EXPECT_TRUE(ok.unused.empty());
  const auto typo =
      check_petsc_options(std::string(split) + " -fieldsplit_arteri_pc_type jacobi", {"balloon", "artery"});
  EXPECT_EQ(typo.error, "");
  EXPECT_EQ(typo.unused, std::vector<std::string>{"-fieldsplit_arteri_pc_type"});
}

// newton.reuse_parts (consistency with the default solver): the artery's split keeps the LU
// factorization of an earlier tangent while the balloon's is renewed with every tangent; FGMRES
// around the block Gauss-Seidel reaches the same state. That the artery's factorization really
// survives the steps (also the matrix's pattern growth as contact starts) is read from PETSc: the
// artery split's factored matrix is the same object in the same state after several steps, the
// balloon's is not. With a small lag the kept factorization is renewed, and the state is still the same.
TEST(BalloonArtery, KeptArterySplitGivesTheSameState) {
  const BAResult a = balloon_artery_run(PETSC_COMM_WORLD);
  const std::string split =
      by_parts + "-ksp_max_it 400 -fieldsplit_artery_ksp_type preonly -fieldsplit_artery_pc_type lu";
  const BAResult b = balloon_artery_run(PETSC_COMM_WORLD, split, [](NewtonOptions& n) {
    n.reuse_preconditioner = 300;  // above what FGMRES needs here to the test's 1e-13 (up to ~120): never renewed
    n.reuse_parts = {"artery"};
  });
  ASSERT_TRUE(a.converged) << a.failure;
  ASSERT_TRUE(b.converged) << b.failure;
  // both states meet Newton's rtol 1e-10 of the first residual: they may differ by that much, not
  // more (measured: 1e-15 displacement, 3e-14 contact force, relative, on 1 and 2 ranks)
  EXPECT_NEAR(b.max_u, a.max_u, 1e-10 * a.max_u);
  EXPECT_NEAR(b.force_magnitude, a.force_magnitude, 1e-10 * a.force_magnitude);
  EXPECT_EQ(b.active, a.active);
  EXPECT_GT(b.pattern_rebuilds, 0);  // contact grew the matrix while the artery's factorization was kept
  // one setup of the kept split (the first solve), every Newton iteration's tangent for the balloon
  EXPECT_EQ(b.factorizations, 1);
  EXPECT_GT(b.newton_iterations, 4);
  ASSERT_EQ(b.split_factors.size(), 4u);
  ASSERT_EQ(b.split_factors.front().size(), 2u);  // balloon, artery (the mesh's part order)
  EXPECT_EQ(b.split_factors.back()[1], b.split_factors.front()[1]);
  EXPECT_NE(b.split_factors.back()[0], b.split_factors.front()[0]);
  // renewed where FGMRES needs more than 20 iterations with the old factorization (the contact's onset)
  const BAResult c = balloon_artery_run(PETSC_COMM_WORLD, split, [](NewtonOptions& n) {
    n.reuse_preconditioner = 20;
    n.reuse_parts = {"artery"};
  });
  ASSERT_TRUE(c.converged) << c.failure;
  EXPECT_NEAR(c.max_u, a.max_u, 1e-10 * a.max_u);
  EXPECT_NEAR(c.force_magnitude, a.force_magnitude, 1e-10 * a.force_magnitude);
  EXPECT_EQ(c.active, a.active);
  EXPECT_GT(c.factorizations, 1);                    // renewed (measured 8 on 1 rank, 9 on 2)
  EXPECT_LT(c.factorizations, c.newton_iterations);  // and kept in between (34 Newton iterations)
  EXPECT_NE(c.split_factors.back()[1], c.split_factors.front()[1]);
}

// Scene section validation: defaults, `off`, typos named with their key path.
TEST(ContactScene, ReadsAndValidates) {
  auto node = [](const char* y) { return angio::scene::Node(YAML::Load(y), "s.yaml", ""); };
  {
    const auto s = read_contact_spec(node("time: {end: 1}"));
    EXPECT_EQ(*s.stent_balloon, 10.0);
    EXPECT_EQ(*s.stent_artery, 10.0);
    ASSERT_TRUE(s.balloon_artery);
    EXPECT_EQ(s.balloon_artery->penalty, 5.0);
  }
  {
    const auto s = read_contact_spec(
        node("contact: {stent_balloon: {penalty: 20}, stent_artery: off, balloon_artery: {penalty: 7, quadrature: 5}, "
             "search_radius: 0.2}"));
    EXPECT_EQ(*s.stent_balloon, 20.0);
    EXPECT_FALSE(s.stent_artery);
    EXPECT_EQ(s.balloon_artery->penalty, 7.0);
    EXPECT_EQ(s.balloon_artery->quadrature, 5);
    EXPECT_EQ(s.balloon_artery->search_radius, 0.2);
    EXPECT_EQ(s.search_radius, 0.2);
    EXPECT_EQ(s.balloon_artery->slave, "balloon_outer");
    EXPECT_EQ(s.balloon_artery->regularization, 0.0);
  }
  {  // the lumen's Gauss points projected onto the balloon; the C1 law below 10 µm
    const auto s = read_contact_spec(node("contact: {balloon_artery: {slave: artery, regularization: 0.01}}"));
    EXPECT_EQ(s.balloon_artery->slave, "artery_inner");
    EXPECT_EQ(s.balloon_artery->master, "balloon_outer");
    EXPECT_EQ(s.balloon_artery->regularization, 0.01);
  }
  auto error = [&](const char* y) {
    try {
      read_contact_spec(node(y));
    } catch (const angio::scene::SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("contact: {stent_balon: {penalty: 1}}").find("contact.stent_balon"), std::string::npos);
  EXPECT_NE(error("contact: {stent_balloon: {penalty: -1}}").find("contact.stent_balloon.penalty"), std::string::npos);
  EXPECT_NE(error("contact: {balloon_artery: {penalti: 1}}").find("contact.balloon_artery.penalti"), std::string::npos);
  EXPECT_NE(error("contact: {search_radius: 0}").find("contact.search_radius"), std::string::npos);
  EXPECT_NE(error("contact: {balloon_artery: {slave: stent}}").find("contact.balloon_artery.slave"), std::string::npos);
  EXPECT_NE(error("contact: {balloon_artery: {regularization: 0.2}}").find("contact.balloon_artery.regularization"),
            std::string::npos);
  EXPECT_NE(error("contact: {stent_artery: maybe}").find("contact.stent_artery"), std::string::npos);
  EXPECT_NE(error("contact: {line_tangent: full}").find("contact.line_tangent"), std::string::npos);
  EXPECT_FALSE(read_contact_spec(node("time: {end: 1}")).line_ring_tangent);  // face: the default
  EXPECT_TRUE(read_contact_spec(node("contact: {line_tangent: ring}")).line_ring_tangent);
  EXPECT_TRUE(read_contact_spec(node("time: {end: 1}")).line_force_tangent);
  EXPECT_FALSE(read_contact_spec(node("contact: {line_tangent: gap}")).line_force_tangent);
  EXPECT_FALSE(read_contact_spec(node("contact: {line_tangent: gap}")).line_ring_tangent);
  EXPECT_FALSE(read_contact_spec(node("contact: {line_tangent: gap}")).line_definite_force_terms);
  const ContactSpec definite = read_contact_spec(node("contact: {line_tangent: definite}"));
  EXPECT_TRUE(definite.line_force_tangent && definite.line_definite_force_terms);
  EXPECT_FALSE(definite.line_ring_tangent);
}

// The shipped scene parses (solid parts + contact section) and enables balloon-artery contact.
TEST(ContactScene, ShippedBalloonInArteryScene) {
  const auto root = angio::scene::load_scene(std::string(ANGIO_CONFIGS_DIR) + "/solid_balloon_in_artery.yaml");
  const SolidScene sc = read_solid_scene(root);
  EXPECT_TRUE(sc.has_balloon && sc.has_artery);
  const ContactSpec spec = read_contact_spec(root);
  ASSERT_TRUE(spec.balloon_artery);
  EXPECT_EQ(spec.balloon_artery->penalty, 50.0);
  EXPECT_EQ(*spec.stent_balloon, 10.0);
}
