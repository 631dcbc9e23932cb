// Tests of the distributed solid model (PETSc + MPI). Run under mpirun with 1 or 2 ranks.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>
#include <petscsys.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <numeric>
#include <numbers>
#include <iterator>
#include <sstream>
#include <type_traits>

#include <unistd.h>

#include "angio/scene/node.hpp"
#include "angio/solid/model.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/scene.hpp"
#include "mpi_test.hpp"

using namespace angio::solid;

namespace angio_test {
Mesh cube_mesh(ElemType t, int n, double perturb, unsigned seed);
}

using angio_test::world_rank;
using angio_test::world_size;

namespace {
// The element faces on the cube face x = 1, as surface set "right".
SurfaceSet faces_at_x1(const Mesh& m) {
  SurfaceSet right{"right", {}};
  for (const auto& el : m.elements)
    for (const auto& lf : local_faces(el.type)) {
      Face f;
      f.type = lf.type;
      bool on = true;
      for (size_t a = 0; a < lf.nodes.size(); ++a) {
        f.n[a] = el.n[lf.nodes[a]];
        on = on && std::abs(m.X[f.n[a]].x() - 1.0) < 1e-12;
      }
      if (on) right.faces.push_back(f);
    }
  return right;
}

// Nodal displacements of a model, by mesh node, on every rank (collective).
std::vector<Vec3d> displacements(const SolidModel& model) { return model.gather_displacement(); }
double max_norm(const std::vector<Vec3d>& a) {
  double d = 0.0;
  for (const auto& v : a) d = std::max(d, v.norm());
  return d;
}
double max_diff(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b) {
  double d = 0.0;
  for (size_t n = 0; n < a.size(); ++n) d = std::max(d, (a[n] - b[n]).norm());
  return d;
}

// A whole dataset of an HDF5 file (serial read, rank 0), flattened row by row; empty if absent.
template <class T>
std::vector<T> read_dataset(const std::string& file, const std::string& path) {
  std::vector<T> v;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return v;
  if (H5Lexists(f, path.c_str(), H5P_DEFAULT) > 0) {
    const hid_t ds = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    v.resize(size_t(H5Sget_simple_extent_npoints(space)));
    const hid_t type = std::is_same_v<T, int> ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE;
    if (H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0) v.clear();
    H5Sclose(space);
    H5Dclose(ds);
  }
  H5Fclose(f);
  return v;
}

ModelOptions direct_options() {
  ModelOptions o;
  o.petsc_options = "-ksp_rtol 1e-12";
  o.newton.rtol = 1e-10;
  o.newton.atol = 1e-12;
  return o;
}

// A thick tube "cyl" (inner radius a, wall b - a in n_radial elements) along z, and the plane-strain
// supports of the thick-cylinder problem: no axial motion, symmetry on the planes x = 0 and y = 0.
Mesh thick_tube(double a, double b, int n_radial, int n_circ, int n_axial, double length) {
  TubeSpec s;
  s.part = "cyl";
  s.surface_prefix = "cyl_";
  s.length = length;
  s.inner_radius = a;
  s.layers = {{"wall", b - a, n_radial}};
  s.n_circ = n_circ;
  s.n_axial = n_axial;
  return make_tube(s);
}
void plane_strain_supports(SolidModel& model, const Mesh& m) {
  std::vector<int> all(m.X.size()), xzero, yzero;
  for (size_t n = 0; n < m.X.size(); ++n) {
    all[n] = int(n);
    if (std::abs(m.X[n].x()) < 1e-9) xzero.push_back(int(n));
    if (std::abs(m.X[n].y()) < 1e-9) yzero.push_back(int(n));
  }
  auto zero = [](const Vec3d&, double) { return 0.0; };
  model.add_dirichlet({all, 2, zero});
  model.add_dirichlet({xzero, 0, zero});
  model.add_dirichlet({yzero, 1, zero});
}

// The distorted unit cube pressed by a follower pressure p on the face x = 1, rollers on the
// planes x = 0, y = 0, z = 0, at t = 1.
std::unique_ptr<SolidModel> pressed_cube(const Mesh& m, const LayerMaterial& mat, const ModelOptions& o, double p) {
  Mesh mm = m;
  mm.surfaces.push_back(faces_at_x1(mm));
  mm.orient_surfaces();
  auto model = std::make_unique<SolidModel>(PETSC_COMM_WORLD, mm, std::vector<LayerMaterial>{mat}, o);
  for (int c = 0; c < 3; ++c) {
    std::vector<int> plane;
    for (size_t n = 0; n < mm.X.size(); ++n)
      if (std::abs(mm.X[n](c)) < 1e-12) plane.push_back(int(n));
    model->add_dirichlet({plane, c, [](const Vec3d&, double) { return 0.0; }});
  }
  model->add_pressure({"right", [p](double) { return p; }});
  model->set_time(1.0);
  return model;
}
}  // namespace

// Nodes a rank holds only from a later hold_nodes() (a contact surface set after a continued run's
// state was applied) take their owners' current and committed displacement: consistency of the held
// state across ranks (on 2 ranks each rank holds fewer nodes than the mesh before).
TEST(Model, NodesHeldLaterTakeTheirOwnersDisplacement) {
  const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 4, 0.08, 5);
  SolidModel model(PETSC_COMM_WORLD, m, {LayerMaterial{"cube", {1.0, 0.3}, {}}}, direct_options());
  auto field = [&](double s) {  // a different displacement per node and per s
    std::vector<Vec3d> u(m.X.size());
    for (size_t n = 0; n < u.size(); ++n)
      u[n] = s * Vec3d(0.01 * m.X[n].y(), 0.001 * double(n) - 0.02 * m.X[n].z(), 0.03 * m.X[n].x());
    return u;
  };
  model.start_from(0.5, field(2.0), field(1.0), 0.25);  // committed field(2), the commit before field(1)
  model.set_displacement(field(3.0));                   // current, on the nodes held so far
  const int held_before = model.num_held_nodes();
  int size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (size > 1) {
    EXPECT_LT(held_before, int(m.X.size()));
  }
  std::vector<int> all(m.X.size());
  std::iota(all.begin(), all.end(), 0);
  model.hold_nodes(all);
  ASSERT_EQ(model.num_held_nodes(), int(m.X.size()));
  const std::vector<Vec3d> current = field(3.0), committed = field(2.0), before = field(1.0);
  double d = 0.0;
  for (size_t n = 0; n < m.X.size(); ++n) d = std::max(d, (model.displacement(int(n)) - current[n]).norm());
  EXPECT_EQ(d, 0.0);
  ASSERT_TRUE(model.has_commit_before());
  EXPECT_EQ(model.before_time(), 0.25);
  double dc = 0.0, db = 0.0;
  for (size_t n = 0; n < m.X.size(); ++n) {
    dc = std::max(dc, (model.committed_displacement(int(n)) - committed[n]).norm());
    db = std::max(db, (model.displacement_before(int(n)) - before[n]).norm());
  }
  EXPECT_EQ(dc, 0.0);
  EXPECT_EQ(db, 0.0);
  model.rollback();  // the committed state of the newly held nodes too
  d = 0.0;
  for (size_t n = 0; n < m.X.size(); ++n) d = std::max(d, (model.displacement(int(n)) - committed[n]).norm());
  EXPECT_EQ(d, 0.0);
}

// Patch test through the whole distributed path: boundary nodes prescribed to the homogeneous
// finite deformation u = G X (Dirichlet); the interior nodes must follow it exactly.
TEST(Model, PatchTestSolveAllElementTypes) {
  Mat3 G;
  G << 0.12, 0.05, -0.03, 0.02, -0.08, 0.04, 0.06, 0.01, 0.10;
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    Mesh m = angio_test::cube_mesh(t, 3, 0.08, 5);
    const auto boundary = m.node_sets.at("boundary");
    m.frames.assign(m.elements.size(), Frame{});  // homogeneous material (same fiber directions everywhere)
    LayerMaterial mat{"cube", {1.0, 0.4}, {{0.3, 1.0, 20.0, true}}};
    SolidModel model(PETSC_COMM_WORLD, m, {mat}, direct_options());
    for (int c = 0; c < 3; ++c)
      model.add_dirichlet({boundary, c, [G, c](const Vec3d& X, double t) { return t * (G * X)(c); }});
    // two load steps: each prescribed increment is lifted through a linearised predictor
    for (double time : {0.5, 1.0}) {
      model.set_time(time);
      const SolveReport rep = model.solve();
      ASSERT_TRUE(rep.converged) << name(t) << ": " << rep.message;
      model.commit();
    }
    double err = 0;
    const std::vector<Vec3d> u = displacements(model);
    for (size_t n = 0; n < m.X.size(); ++n) err = std::max(err, (u[n] - G * m.X[n]).norm());
    EXPECT_LT(err, 1e-8) << name(t);
  }
}

// The element tangents added straight into the matrix's arrays (MatrixSlots) give the matrix that
// MatSetValues gives, entry for entry and bit for bit (the same sums in the same order), on a deformed
// distorted cube with a follower pressure; on 2 ranks the element graph's partition puts entries in
// the off-diagonal block and rows on the other rank. Consistency: two insertion paths, one matrix.
TEST(Model, DirectInsertionGivesTheMatrixOfMatSetValues) {
  for (ElemType t : {ElemType::Hex8, ElemType::Tet10}) {
    Mesh m = angio_test::cube_mesh(t, 4, 0.08, 5);
    m.surfaces.push_back(faces_at_x1(m));
    m.orient_surfaces();
    LayerMaterial mat{"cube", {1.0, 0.4}, {{0.3, 1.0, 20.0, true}}};
    ModelOptions o = direct_options();
    o.partitioner = "ptscotch";
    SolidModel model(PETSC_COMM_WORLD, m, {mat}, o);
    model.add_pressure({"right", [](double) { return 0.05; }});
    model.set_time(1.0);
    std::vector<Vec3d> u(m.X.size());
    for (size_t n = 0; n < u.size(); ++n) {
      const Vec3d& X = m.X[n];
      u[n] = Vec3d(0.1 * std::sin(2.0 * X.y()) * X.z(), 0.08 * X.x() * X.x(), -0.05 * std::cos(X.x() + X.y()));
    }
    model.set_displacement(u);
    ASSERT_TRUE(model.direct_insertion()) << name(t);
    Mat K = model.matrix(), K2 = nullptr;
    ASSERT_EQ(0, MatDuplicate(K, MAT_DO_NOT_COPY_VALUES, &K2));
    ASSERT_EQ(0, MatSetOption(K2, MAT_ROW_ORIENTED, PETSC_FALSE));  // as K_: Eigen's column-major element matrices
    Vec r2 = nullptr;
    ASSERT_EQ(0, VecDuplicate(model.residual_vector(), &r2));
    ASSERT_TRUE(model.assemble(model.residual_vector(), K));  // K_: through the slots
    ASSERT_TRUE(model.assemble(r2, K2));                      // another matrix: through MatSetValues
    PetscReal norm = 0.0, diff = -1.0;
    ASSERT_EQ(0, MatNorm(K, NORM_INFINITY, &norm));
    ASSERT_EQ(0, MatAXPY(K2, -1.0, K, SAME_NONZERO_PATTERN));
    ASSERT_EQ(0, MatNorm(K2, NORM_INFINITY, &diff));
    EXPECT_GT(norm, 1.0) << name(t);
    EXPECT_EQ(diff, 0.0) << name(t);
    MatDestroy(&K2);
    VecDestroy(&r2);
  }
}

// Uniaxial compression of a distorted unit cube by a small follower pressure p on the face x = 1
// (quad4 / tri3 / tri6 faces), rollers on x = 0, y = 0, z = 0: compared with the linear-elastic
// solution u_x(1) = -p/E, u_y(y=1) = +nu p/E (homogeneous stress, exact for every element type up to
// the O(p^2) geometric nonlinearity).
TEST(Model, PressureOnCubeAllFaceTypes) {
  const double E = 2.0, nu = 0.3, p = 2e-5;
  for (ElemType t : {ElemType::Hex8, ElemType::Tet4, ElemType::Tet10}) {
    const Mesh m = angio_test::cube_mesh(t, 2, 0.08, 9);
    ASSERT_FALSE(faces_at_x1(m).faces.empty());
    auto model = pressed_cube(m, LayerMaterial{"cube", {E, nu}, {}}, direct_options(), p);
    const auto rep = model->solve();
    ASSERT_TRUE(rep.converged) << rep.message;
    const std::vector<Vec3d> un = displacements(*model);
    for (size_t n = 0; n < m.X.size(); ++n) {
      const Vec3d X = m.X[n], u = un[n];
      EXPECT_NEAR(u.x(), -p / E * X.x(), 1e-3 * p / E) << name(t);
      EXPECT_NEAR(u.y(), nu * p / E * X.y(), 1e-3 * p / E) << name(t);
    }
  }
}

// Damping (NewtonOptions::damping) is artificial viscosity over the pseudo-time.
// Consistency: (1) the first damped solve stops short of the equilibrium and reports the force it
// needed; (2) repeated solve + commit at the same load while the time advances is a proximal-point
// iteration whose fixed point is the undamped equilibrium (the viscous force vanishes at rest), so
// it converges to the solution without damping; (3) Newton stays quadratic with the added diagonal
// (few iterations per solve), which checks the tangent term; (4) the force is viscous: η with Δt
// gives exactly the solution of 2η with 2Δt, and the same η over half the step damps harder.
TEST(Model, DampingConvergesToTheEquilibrium) {
  const double p = 0.05;
  auto solve_cube = [&](double eta, double dt, int cycles, std::vector<double>& force, int& max_newton) {
    const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 2, 0.08, 9);
    ModelOptions o = direct_options();
    o.newton.damping = eta;
    auto model = pressed_cube(m, LayerMaterial{"cube", {2.0, 0.3}, {}}, o, p);
    model->start_at(0.0);
    max_newton = 0;
    for (int i = 0; i < cycles; ++i) {
      model->set_time((i + 1) * dt);
      const auto rep = model->solve();
      EXPECT_TRUE(rep.converged) << rep.message;
      force.push_back(rep.damping_force);
      max_newton = std::max(max_newton, rep.iterations);
      model->commit();
    }
    return displacements(*model);
  };
  std::vector<double> f0, f;
  int it0 = 0, it = 0;
  const auto u_ref = solve_cube(0.0, 1.0, 1, f0, it0);
  double scale = 0;
  for (const auto& v : u_ref) scale = std::max(scale, v.norm());
  const auto u1 = solve_cube(0.5, 1.0, 1, f, it);
  const double err1 = max_diff(u1, u_ref);
  EXPECT_GT(err1, 0.05 * scale);  // one damped solve stops visibly short
  EXPECT_GT(f[0], 0.0);
  std::vector<double> g;
  EXPECT_LT(max_diff(solve_cube(1.0, 2.0, 1, g, it), u1), 1e-12 * scale);  // η/Δt is what counts
  EXPECT_GT(max_diff(solve_cube(0.5, 0.5, 1, g, it), u_ref), 1.2 * err1);  // a shorter step damps harder
  f.clear();
  const auto u = solve_cube(0.5, 1.0, 20, f, it);
  EXPECT_LT(max_diff(u, u_ref), 1e-8 * scale);
  EXPECT_LT(f.back(), 1e-6 * f.front());
  EXPECT_LE(it, it0 + 1);  // quadratic Newton with the damping tangent
  EXPECT_EQ(f0[0], 0.0);   // off by default
}

// newton.damping_parts, consistency: damping restricted to a part the mesh does not have gives the
// undamped solution exactly (no damping force), restricted to the mesh's own part the globally
// damped one.
TEST(Model, DampingPartsSelectTheDampedElements) {
  const double p = 0.05;
  auto solve = [&](double eta, std::vector<std::string> parts, double& force) {
    const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 2, 0.08, 9);  // one block, part "test"
    ModelOptions o = direct_options();
    o.newton.damping = eta;
    o.newton.damping_parts = std::move(parts);
    auto model = pressed_cube(m, LayerMaterial{"cube", {2.0, 0.3}, {}}, o, p);
    model->start_at(0.0);
    model->set_time(1.0);
    const auto rep = model->solve();
    EXPECT_TRUE(rep.converged) << rep.message;
    force = rep.damping_force;
    return displacements(*model);
  };
  double f_none = -1, f_all = -1, f_other = -1, f_own = -1;
  const auto u_none = solve(0.0, {}, f_none);
  const auto u_all = solve(0.5, {}, f_all);
  const auto u_other = solve(0.5, {"balloon"}, f_other);
  const auto u_own = solve(0.5, {"test"}, f_own);
  double scale = 0;
  for (const auto& v : u_none) scale = std::max(scale, v.norm());
  EXPECT_GT(max_diff(u_all, u_none), 0.05 * scale);  // the damping acts
  EXPECT_EQ(f_other, 0.0);
  EXPECT_LT(max_diff(u_other, u_none), 1e-12 * scale);
  EXPECT_GT(f_own, 0.0);
  EXPECT_LT(max_diff(u_own, u_all), 1e-12 * scale);
}

// Lagged preconditioner (newton.reuse_preconditioner), consistency: GMRES preconditioned with the
// LU factorization of an earlier tangent converges to the same solution as a fresh LU at every Newton
// iteration (same load steps, fibers in tension), with fewer factorizations than Newton iterations,
// and Newton still converges in as many iterations (the tangent itself is exact).
TEST(Model, ReusedPreconditionerGivesTheSameSolution) {
  const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 3, 0.08, 9);
  const LayerMaterial mat{"cube", {2.0, 0.3}, {{0.4, 1.5, 20.0, true}}};
  auto run = [&](const std::string& petsc, int lag, int& newton, int& setups) {
    ModelOptions o = direct_options();
    o.petsc_options = petsc;
    o.newton.reuse_preconditioner = lag;
    auto model = pressed_cube(m, mat, o, 0.0);
    model->add_pressure({"right", [](double t) { return -0.3 * t; }});  // tension, growing with t
    model->start_at(0.0);
    newton = setups = 0;
    for (int i = 1; i <= 4; ++i) {
      model->set_time(0.25 * i);
      const auto rep = model->solve();
      EXPECT_TRUE(rep.converged) << rep.message;
      newton += rep.iterations;
      setups += rep.factorizations;
      model->commit();
    }
    return displacements(*model);
  };
  int n0, s0, n1, s1;
  const auto u0 = run("-ksp_type preonly -pc_type lu", 0, n0, s0);
  const auto u1 = run("-ksp_type gmres -ksp_rtol 1e-12 -pc_type lu", 10, n1, s1);
  const double scale = max_norm(u0);
  EXPECT_GT(scale, 0.05);
  EXPECT_LT(max_diff(u0, u1), 1e-9 * scale);
  EXPECT_EQ(s0, n0);  // one factorization per Newton iteration without reuse
  EXPECT_LT(s1, n1);
  EXPECT_LE(n1, n0 + 1);
}

// Modified Newton (newton.tangent: modified), consistency: keeping the factorization of an earlier
// tangent across iterations and steps converges to the same solution as exact Newton (same load
// steps, fibers in tension, tolerance 1e-10 relative) with fewer factorizations than steps, and its
// iterations assemble the residual only. A max_contraction that no iteration can meet (1e-12)
// refactorizes after every iteration: every iteration but a step's first (which starts from the
// previous step's factorization) is then an exact Newton iteration.
TEST(Model, ModifiedNewtonGivesTheSameSolutionWithFewerFactorizations) {
  const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 3, 0.08, 9);
  const LayerMaterial mat{"cube", {2.0, 0.3}, {{0.4, 1.5, 20.0, true}}};
  auto run = [&](bool modified, double contraction, SolveTotals& tot) {
    ModelOptions o = direct_options();
    o.petsc_options = "-ksp_type preonly -pc_type lu";
    o.newton.rtol = 1e-10;
    o.newton.atol = 1e-13;
    o.newton.max_iterations = 60;
    o.newton.modified = modified;
    o.newton.max_contraction = contraction;
    auto model = pressed_cube(m, mat, o, 0.0);
    model->add_pressure({"right", [](double t) { return -0.3 * t; }});  // tension, growing with t
    model->start_at(0.0);
    for (int i = 1; i <= 8; ++i) {
      model->set_time(0.125 * i);
      const auto rep = model->solve();
      EXPECT_TRUE(rep.converged) << rep.message;
      tot.add(rep);
      model->commit();
    }
    return displacements(*model);
  };
  SolveTotals exact, mod, strict;
  const auto u0 = run(false, 0.25, exact);
  const auto u1 = run(true, 0.5, mod);
  const auto u2 = run(true, 1e-12, strict);
  const double scale = max_norm(u0);
  EXPECT_GT(scale, 0.05);
  EXPECT_LT(max_diff(u0, u1), 1e-9 * scale);
  EXPECT_LT(max_diff(u0, u2), 1e-9 * scale);
  EXPECT_EQ(exact.factorizations, exact.newton_iterations);
  // exact Newton: one tangent per iteration, assembled where the iteration starts (a solve's first
  // residual and line-search trials are residuals alone; none where the solve has converged)
  EXPECT_EQ(exact.tangent_assemblies, exact.newton_iterations);
  EXPECT_LT(mod.factorizations, 8);                           // fewer than one per step
  EXPECT_GT(mod.newton_iterations, exact.newton_iterations);  // linear instead of quadratic convergence
  EXPECT_LT(mod.tangent_assemblies, mod.newton_iterations);   // most iterations: residual only
  EXPECT_GE(strict.factorizations, strict.newton_iterations - 7);
  EXPECT_LE(strict.factorizations, strict.newton_iterations);
}

// Viscous branch (eqs. B.5–B.8) through the model (commit/rollback of the history), consistency
// properties under a constant follower pressure on the cube: (1) a step of vanishing Δt answers
// with S = S∞ + β Sv, i.e. exactly the elastic solution of the material with E scaled by 1 + β
// (branch on the isotropic Neo-Hooke stress, the default) or E and k1 scaled by 1 + β (acts_on
// all); (2) held at that load the cube creeps monotonically and converges to the elastic
// equilibrium of S∞ alone (Q relaxes to 0); (3) a rejected step (rollback) leaves the history
// untouched: the same step solved again gives the same displacement.
TEST(Model, ViscousBranchCreepsToTheElasticEquilibrium) {
  const double p = 0.05, beta = 0.3;
  const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 2, 0.08, 9);
  auto elastic = [&](double scale_matrix, double scale_fibers) {
    auto model =
        pressed_cube(m, LayerMaterial{"cube", {2.0 * scale_matrix, 0.3}, {{0.4 * scale_fibers, 1.5, 20.0, true}}},
                     direct_options(), p);
    EXPECT_TRUE(model->solve().converged);
    return displacements(*model);
  };
  const auto u_inf = elastic(1.0, 1.0), u_0 = elastic(1.0 + beta, 1.0);
  double scale = 0;
  for (const auto& v : u_inf) scale = std::max(scale, v.norm());
  {  // acts_on all: instantaneous response of the material with E and k1 scaled by 1 + β
    LayerMaterial all{"cube", {2.0, 0.3}, {{0.4, 1.5, 20.0, true}}, ViscousBranch{0.5, beta, ViscousActsOn::all}};
    auto model = pressed_cube(m, all, direct_options(), p);
    model->start_at(0.0);
    model->set_time(1e-10);
    ASSERT_TRUE(model->solve().converged);
    const auto u_0_all = elastic(1.0 + beta, 1.0 + beta);
    EXPECT_LT(max_diff(displacements(*model), u_0_all), 1e-8 * scale);
    EXPECT_GT(max_diff(u_0_all, u_0), 1e-4 * scale);  // the fibers are loaded: the placements differ
  }

  LayerMaterial visc{"cube", {2.0, 0.3}, {{0.4, 1.5, 20.0, true}}, ViscousBranch{0.5, beta}};
  auto model = pressed_cube(m, visc, direct_options(), p);
  model->start_at(0.0);
  model->set_time(1e-10);
  ASSERT_TRUE(model->solve().converged);
  EXPECT_LT(max_diff(displacements(*model), u_0), 1e-8 * scale);
  model->commit();

  double t = 1e-10, previous = 0.0;
  for (int i = 0; i < 100; ++i) {
    t += 0.1;
    model->set_time(t);
    ASSERT_TRUE(model->solve().converged);
    if (i == 3) {  // reject once and solve the same step again
      const auto first = displacements(*model);
      model->rollback();
      ASSERT_TRUE(model->solve().converged);
      EXPECT_LT(max_diff(displacements(*model), first), 1e-12 * scale);
    }
    model->commit();
    const double d = max_diff(displacements(*model), u_0);
    EXPECT_GE(d, previous - 1e-14);  // creeps away from the instantaneous response, monotonically
    previous = d;
  }
  // 10 s = 15 retardation times τ(1 + β) of the linearized model: e^(−15) ≈ 3e-7
  EXPECT_LT(max_diff(displacements(*model), u_inf), 1e-5 * scale);
  EXPECT_GT(max_diff(u_0, u_inf), 0.1 * scale);  // the two limits are far apart
}

// The thick-walled cylinder of the Lamé tests (a = 1, b = 2, E = 1, nu = 0.3, plane strain, hex8)
// under the inner pressure p, on springs of stiffness k per unit area on its outer surface (0: none):
// the largest error of the radial displacement against ur(r), relative to ur(a).
namespace {
constexpr double kLameA = 1.0, kLameB = 2.0, kLameE = 1.0, kLameNu = 0.3;
double lame_cylinder_error(double p, double k, const std::function<double(double)>& ur) {
  const Mesh m = thick_tube(kLameA, kLameB, 8, 64, 1, 0.2);
  SolidModel model(PETSC_COMM_WORLD, m, {LayerMaterial{"wall", {kLameE, kLameNu}, {}}}, direct_options());
  plane_strain_supports(model, m);
  model.add_pressure({"cyl_inner", [p](double t) { return p * t; }});
  if (k > 0) model.add_springs({"cyl_outer", k});
  model.set_time(1.0);
  const SolveReport rep = model.solve();
  EXPECT_TRUE(rep.converged) << rep.message;
  double max_rel = 0;
  const std::vector<Vec3d> un = displacements(model);
  for (size_t n = 0; n < m.X.size(); ++n) {
    const Vec3d X = m.X[n];
    const double r = std::hypot(X.x(), X.y());
    const Vec3d u = un[n];
    const double urn = (u.x() * X.x() + u.y() * X.y()) / r;
    max_rel = std::max(max_rel, std::abs(urn - ur(r)) / ur(kLameA));
  }
  return max_rel;
}
}  // namespace

// Thick-walled cylinder, plane strain, small internal pressure: compared with Lame's linear-elastic
// solution u_r(r) = (1+nu)/E [(1-2nu) A r + B/r], A = p a^2/(b^2-a^2), B = p a^2 b^2/(b^2-a^2).
TEST(Model, ThickCylinderMatchesLame) {
  const double a = kLameA, b = kLameB, E = kLameE, nu = kLameNu, p = 1e-4;
  const double A = p * a * a / (b * b - a * a), B = p * a * a * b * b / (b * b - a * a);
  auto ur = [&](double r) { return (1 + nu) / E * ((1 - 2 * nu) * A * r + B / r); };
  EXPECT_LT(lame_cylinder_error(p, 0.0, ur), 0.01);  // faceted circle (64 sides) and hex8 discretisation error
}

// The same cylinder on an elastic foundation (springs of stiffness k per unit area on the outer
// surface, as artery.tissue_support): Lamé's u_r = C1 r + C2 / r with sigma_r(a) = -p and
// sigma_r(b) = -k u_r(b), plane strain sigma_r = 2 (lambda + mu) C1 - 2 mu C2 / r^2. The foundation
// takes a third of the inner displacement away (k = 0.5: u_r(a) 1.214e-4 against 1.907e-4).
TEST(Model, ThickCylinderOnElasticFoundationMatchesLame) {
  const double a = kLameA, b = kLameB, E = kLameE, nu = kLameNu, p = 1e-4, k = 0.5;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  // [2(λ+μ), −2μ/a²; 2(λ+μ) + k b, −2μ/b² + k/b] (C1, C2) = (−p, 0)
  const double m11 = 2 * (lambda + mu), m12 = -2 * mu / (a * a), m21 = m11 + k * b, m22 = -2 * mu / (b * b) + k / b;
  const double det = m11 * m22 - m12 * m21;
  const double C1 = -p * m22 / det, C2 = p * m21 / det;
  auto ur = [&](double r) { return C1 * r + C2 / r; };
  const double free_ua = (1 + nu) / E * p * a * a / (b * b - a * a) * ((1 - 2 * nu) * a + b * b / a);
  EXPECT_LT(ur(a), 0.7 * free_ua);                 // the foundation matters in this test
  EXPECT_LT(lame_cylinder_error(p, k, ur), 0.01);  // as the free cylinder
}

// Near incompressibility (ν = 0.499, hex8 with full integration: the volumetric terms dominate ||r||),
// a thick tube under internal pressure in one step: the energy merit of the line search reaches the
// same equilibrium as the residual merit (consistency) in fewer Newton iterations (measured 6 against
// 17; at 5 x the pressure the residual merit did not converge in 60).
TEST(Model, EnergyLineSearchMeritNearIncompressibility) {
  const Mesh m = thick_tube(1.0, 1.5, 3, 32, 3, 0.5);
  auto run = [&](bool energy, SolveReport& rep) {
    ModelOptions o = direct_options();
    o.petsc_options = "-ksp_type preonly -pc_type lu";
    o.newton.max_iterations = 60;
    o.newton.energy_line_search = energy;
    SolidModel model(PETSC_COMM_WORLD, m, {LayerMaterial{"cyl", {1.0, 0.499}, {}}}, o);
    plane_strain_supports(model, m);
    model.add_pressure({"cyl_inner", [](double t) { return 0.02 * t; }});
    model.set_time(1.0);
    rep = model.solve();
    return displacements(model);
  };
  SolveReport residual, energy;
  const auto u_r = run(false, residual);
  const auto u_e = run(true, energy);
  ASSERT_TRUE(residual.converged) << residual.message << " (" << residual.iterations << " iterations)";
  ASSERT_TRUE(energy.converged) << energy.message << " (" << energy.iterations << " iterations)";
  const double scale = max_norm(u_r);
  EXPECT_GT(scale, 0.01);
  EXPECT_LT(max_diff(u_r, u_e), 1e-8 * scale);
  EXPECT_LT(energy.iterations, residual.iterations);
  std::printf("near incompressibility: %d Newton iterations (residual merit), %d (energy merit)\n", residual.iterations,
              energy.iterations);
}

// The same nonlinear problem (two-layer fibered tube under internal follower pressure, springs on
// the ends) on all ranks of the world communicator and on one rank gives the same displacements.
TEST(Model, OneAndTwoRanksGiveSameDisplacements) {
  if (world_size() < 2) GTEST_SKIP() << "needs 2 MPI ranks";
  TubeSpec s;
  s.part = "artery";
  s.surface_prefix = "artery_";
  s.length = 3.0;
  s.inner_radius = 0.8;
  s.layers = {{"media", 0.3, 1}, {"adventitia", 0.3, 1}};
  s.n_circ = 16;
  s.n_axial = 8;
  const Mesh m = make_tube(s);
  const std::vector<LayerMaterial> mats = {{"media", {0.1566, 0.45}, {{0.00064, 3.54, 0.0, true}}},
                                           {"adventitia", {0.01566, 0.45}, {{0.0051, 15.4, 40.0, true}}}};
  auto run = [&](MPI_Comm comm, const std::string& partitioner) {
    ModelOptions o = direct_options();
    o.partitioner = partitioner;
    SolidModel model(comm, m, mats, o);
    model.add_pressure({"artery_inner", [](double t) { return 0.03 * t; }});
    model.add_springs({"artery_end0", 1e3});
    model.add_springs({"artery_end1", 1e3});
    for (double t : {0.5, 1.0}) {
      model.set_time(t);
      const auto rep = model.solve();
      EXPECT_TRUE(rep.converged) << rep.message;
      model.commit();
    }
    return displacements(model);
  };
  const auto u_par = run(PETSC_COMM_WORLD, "contiguous");
  const auto u_part = run(PETSC_COMM_WORLD, "ptscotch");
  MPI_Comm serial;
  MPI_Comm_split(PETSC_COMM_WORLD, world_rank() == 0 ? 0 : MPI_UNDEFINED, 0, &serial);
  if (world_rank() == 0) {
    const auto u_ser = run(serial, "contiguous");
    const double umax = max_norm(u_ser);
    EXPECT_GT(umax, 0.01);
    EXPECT_LT(max_diff(u_ser, u_par), 1e-8 * umax);
    EXPECT_LT(max_diff(u_ser, u_part), 1e-8 * umax);
    MPI_Comm_free(&serial);
  }
}

// The fiber frames and fiber directions of the tube's hex8 elements in solid.h5, and as cell
// attributes of every step in solid.xdmf (small_artery.yaml: media fibers at 0°, adventitia ±40°).
static void check_fiber_output(const SolidModel& model, const std::string& dir) {
  const std::string h5 = dir + "/solid.h5";
  const auto id = read_dataset<int>(h5, "/mesh/hex8/original_element_id");
  const auto radial = read_dataset<double>(h5, "/mesh/hex8/frame_radial");
  const auto fiber2 = read_dataset<double>(h5, "/mesh/hex8/fiber_2");
  const Mesh& mesh = model.mesh();
  ASSERT_EQ(id.size(), mesh.elements.size());
  ASSERT_EQ(radial.size(), 3 * id.size());
  ASSERT_EQ(fiber2.size(), 3 * id.size());
  EXPECT_TRUE(read_dataset<double>(h5, "/mesh/hex8/fiber_3").empty());  // two families per layer
  for (size_t i = 0; i < id.size(); ++i) {
    const Frame& f = mesh.frames.at(id[i]);
    EXPECT_LT((Vec3d(radial[3 * i], radial[3 * i + 1], radial[3 * i + 2]) - f.radial).norm(), 1e-15);
    const double deg = mesh.blocks[mesh.elements[id[i]].block].name == "adventitia" ? 40.0 : 0.0;
    const double phi = deg * std::numbers::pi / 180.0;
    const Vec3d a0 = std::cos(phi) * f.circumferential - std::sin(phi) * f.axial;  // the mirrored family
    EXPECT_LT((Vec3d(fiber2[3 * i], fiber2[3 * i + 1], fiber2[3 * i + 2]) - a0).norm(), 1e-14) << "element " << id[i];
  }
  std::ifstream x(dir + "/solid.xdmf");
  const std::string xdmf((std::istreambuf_iterator<char>(x)), {});
  auto count = [&](const std::string& what) {
    size_t n = 0;
    for (size_t at = xdmf.find(what); at != std::string::npos; at = xdmf.find(what, at + 1)) ++n;
    return n;
  };
  const size_t steps = count("<Grid Name=\"step_");
  EXPECT_GE(steps, 2u);
  for (const char* name : {"frame_circumferential", "frame_axial", "frame_radial", "fiber_1", "fiber_2"})
    EXPECT_EQ(count(std::string("Attribute Name=\"") + name + "\" AttributeType=\"Vector\" Center=\"Cell\""), steps)
        << name;
  EXPECT_NE(xdmf.find("solid.h5:/mesh/hex8/fiber_2<"), std::string::npos);
}

// Scene -> runner -> HDF5/XDMF/summary.json on the communicator, two committed steps, one rejected.
TEST(Runner, WritesOutputAndRollsBack) {
  // per rank count: solid.model.np1 and .np2 run this test concurrently in the same directory
  const std::string dir = "solid_runner_test_out_np" + std::to_string(world_size());
  const std::string scene_file = std::string(ANGIO_SOLID_TEST_DATA) + "/small_artery.yaml";
  const auto root = angio::scene::load_scene(scene_file);
  SolidScene sc = read_solid_scene(root);
  SolidRunner runner(PETSC_COMM_WORLD, sc, dir);
  angio::participant::ContactReply reply;
  runner.begin_step(1, 0.5);
  auto st = runner.solve({}, reply, 0.0);
  ASSERT_TRUE(st.converged) << st.message;
  runner.end_step(true);
  const Vec3d u1 = displacements(runner.model())[0];
  runner.begin_step(2, 1.0);
  st = runner.solve({}, reply, 0.0);
  ASSERT_TRUE(st.converged);
  runner.end_step(false);  // rejected: back to step 1
  EXPECT_LT((displacements(runner.model())[0] - u1).norm(), 1e-15);
  st = runner.solve({}, reply, 0.0);
  runner.end_step(true);
  runner.finish();
  ASSERT_EQ(runner.history().size(), 3u);
  // scene `fixed: [{surface: end0, components: [z]}]`
  const auto& f0 = runner.model().mesh().surface("artery_end0")->faces.front();
  const std::vector<Vec3d> u = displacements(runner.model());
  EXPECT_EQ(u[f0.n[0]].z(), 0.0);
  EXPECT_NE(u[f0.n[0]].x(), 0.0);
  EXPECT_GT(runner.history()[2].max_p1[0], runner.history()[1].max_p1[0]);
  MPI_Barrier(PETSC_COMM_WORLD);
  if (world_rank() == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/solid/solid.h5"));
    EXPECT_TRUE(std::filesystem::exists(dir + "/solid/solid.xdmf"));
    std::ifstream f(dir + "/solid/summary.json");
    std::string s((std::istreambuf_iterator<char>(f)), {});
    EXPECT_NE(s.find("\"media\""), std::string::npos);
    EXPECT_NE(s.find("\"step\": 2"), std::string::npos);
    check_fiber_output(runner.model(), dir + "/solid");
  }
}

// Coupled mode: rank 0 drives the participant through MpiSolidParticipant (as the role server
// would), the other ranks run run_follower(); compared with every rank calling the runner directly.
TEST(Runner, LeaderFollowerMatchesCollectiveCalls) {
  if (world_size() < 2) GTEST_SKIP() << "needs 2 MPI ranks";
  const auto root = angio::scene::load_scene(std::string(ANGIO_SOLID_TEST_DATA) + "/small_artery.yaml");
  angio::participant::ContactReply reply;
  angio::participant::SamplePoints pts;
  pts.x = {{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}};
  pts.w = {0.1, 0.1};
  pts.radius = {0.06, 0.06};
  SolidRunner direct(PETSC_COMM_WORLD, read_solid_scene(root), "");
  for (int k = 1; k <= 2; ++k) {
    direct.begin_step(k, 0.5 * k);
    ASSERT_TRUE(direct.solve(pts, reply, 0.0).converged);
    direct.end_step(true);
  }
  SolidRunner coupled(PETSC_COMM_WORLD, read_solid_scene(root), "");
  if (world_rank() == 0) {
    MpiSolidParticipant leader(coupled, PETSC_COMM_WORLD);
    for (int k = 1; k <= 2; ++k) {
      leader.begin_step(k, 0.5 * k);
      const auto st = leader.solve(pts, reply, 0.0);
      EXPECT_TRUE(st.converged);
      EXPECT_EQ(reply.line_loads.size(), 2u);
      leader.end_step(k == 2 ? true : true);
    }
    leader.shutdown();
  } else {
    EXPECT_EQ(run_follower(coupled, PETSC_COMM_WORLD), 0);
  }
  double d = 0;
  const std::vector<Vec3d> ud = displacements(direct.model()), uc = displacements(coupled.model());
  for (size_t n = 0; n < ud.size(); ++n) d = std::max(d, (ud[n] - uc[n]).norm());
  EXPECT_LT(d, 1e-12);
  EXPECT_EQ(coupled.history().size(), 3u);
}

// Bad input is reported with file and key path.
TEST(Scene, ErrorsNameTheKey) {
  const std::string scene_file = std::string(ANGIO_SOLID_TEST_DATA) + "/bad_material.yaml";
  try {
    read_solid_scene(angio::scene::load_scene(scene_file));
    FAIL() << "expected SceneError";
  } catch (const angio::scene::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("artery.layers.media.E"), std::string::npos) << e.what();
  }
}

// viscous.acts_on: absent → the default (isotropic, 4C's VISCO_GenMax placement), `all` is read,
// anything else is refused naming the key and the allowed values.
TEST(Scene, ViscousActsOnIsCheckedAndDefaultsToIsotropic) {
  const std::string base = std::string(ANGIO_SOLID_TEST_DATA) + "/small_artery.yaml";
  std::ifstream in(base);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "media: {E: 0.1566, nu: 0.45, ";
  ASSERT_NE(text.find(key), std::string::npos);
  auto scene_with = [&](const std::string& viscous) {
    std::string t = text;
    t.replace(t.find(key), key.size(), key + "viscous: " + viscous + ", ");
    const std::string path = std::filesystem::temp_directory_path() / ("angio_acts_on_" + std::to_string(getpid()) +
                                                                       "_" + std::to_string(world_rank()) + ".yaml");
    std::ofstream(path) << t;
    return path;
  };
  auto media_branch = [&](const std::string& viscous) {
    const std::string path = scene_with(viscous);
    const SolidScene sc = read_solid_scene(angio::scene::load_scene(path));
    std::filesystem::remove(path);
    for (const auto& mat : sc.materials)
      if (mat.name == "media" && mat.viscous) return *mat.viscous;
    ADD_FAILURE() << "no viscous media in the scene";
    return ViscousBranch{};
  };
  EXPECT_EQ(media_branch("{tau: 0.5, beta: 0.3}").acts_on, ViscousActsOn::isotropic);
  EXPECT_EQ(media_branch("{tau: 0.5, beta: 0.3, acts_on: isotropic}").acts_on, ViscousActsOn::isotropic);
  EXPECT_EQ(media_branch("{tau: 0.5, beta: 0.3, acts_on: all}").acts_on, ViscousActsOn::all);
  for (const std::string bad : {"fibers", "1", "All"}) {
    const std::string path = scene_with("{tau: 0.5, beta: 0.3, acts_on: " + bad + "}");
    try {
      read_solid_scene(angio::scene::load_scene(path));
      ADD_FAILURE() << "expected SceneError for acts_on: " << bad;
    } catch (const angio::scene::SceneError& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find("artery.layers.media.viscous.acts_on"), std::string::npos) << w;
      EXPECT_NE(w.find("isotropic"), std::string::npos) << w;
      EXPECT_NE(w.find("all"), std::string::npos) << w;
    }
    std::filesystem::remove(path);
  }
}

// A physically absurd pressure inside the number type's range (1e6 MPa on the shipped straight scene)
// is refused before anything runs, naming the value's key and the bound.
TEST(Scene, AbsurdBalloonPressureIsRefusedNamingTheValue) {
  std::ifstream in(std::string(ANGIO_CONFIGS_DIR) + "/straight_free_expansion.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "pressure: {value: 1.0, curve: pressure}";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), "pressure: {value: 1.0e6, curve: pressure}");
  const std::string path = std::filesystem::temp_directory_path() / ("angio_pressure_" + std::to_string(getpid()) +
                                                                     "_" + std::to_string(world_rank()) + ".yaml");
  std::ofstream(path) << text;
  try {
    read_solid_scene(angio::scene::load_scene(path));
    ADD_FAILURE() << "expected SceneError";
  } catch (const angio::scene::SceneError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("balloon.pressure.value"), std::string::npos) << w;
    EXPECT_NE(w.find("at most 4 MPa"), std::string::npos) << w;
  }
  std::filesystem::remove(path);
}

// solid.newton.atol is judged against the norm of the peak pressure load (load_scale.hpp): at
// kMaxAtolOfLoad of it the scene is refused naming the key, just below it is accepted. Consistency
// with the scene's own load norm (the straight scene's Newton ladder of bench/work_precision.py: atol ~ the load norm
// accepted every step at iteration 0 and the balloon never inflated).
TEST(Scene, AbsoluteToleranceOfTheOrderOfTheLoadIsRefused) {
  const std::string shipped = std::string(ANGIO_CONFIGS_DIR) + "/solid_free_balloon.yaml";
  std::ifstream in(shipped);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "atol: 1.0e-9";
  ASSERT_NE(text.find(key), std::string::npos);
  const double F = read_solid_scene(angio::scene::load_scene(shipped)).peak_load_norm;
  ASSERT_GT(F, 0.0);
  auto with_atol = [&](double atol) {
    std::string t = text;
    t.replace(t.find(key), key.size(), "atol: " + std::to_string(atol));
    const std::string path = std::filesystem::temp_directory_path() /
                             ("angio_atol_" + std::to_string(getpid()) + "_" + std::to_string(world_rank()) + ".yaml");
    std::ofstream(path) << t;
    return path;
  };
  const std::string loose = with_atol(1.01 * kMaxAtolOfLoad * F);
  try {
    read_solid_scene(angio::scene::load_scene(loose));
    FAIL() << "expected SceneError for atol " << 1.01 * kMaxAtolOfLoad * F << " N against a load of " << F << " N";
  } catch (const angio::scene::SceneError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("solid.newton.atol"), std::string::npos) << w;
    EXPECT_NE(w.find("peak pressure load"), std::string::npos) << w;
  }
  const std::string fine = with_atol(0.99 * kMaxAtolOfLoad * F);
  EXPECT_NO_THROW(read_solid_scene(angio::scene::load_scene(fine)));
  std::filesystem::remove(loose);
  std::filesystem::remove(fine);
}

// An invalid configuration is reported with the element that was found invalid: its index, block and
// where it is (the centroid of that configuration).
TEST(Model, InvalidConfigurationNamesTheElement) {
  const Mesh m = angio_test::cube_mesh(ElemType::Hex8, 2, 0.0, 1);
  LayerMaterial mat{"cube", {1.0, 0.3}, {}};
  SolidModel model(PETSC_COMM_WORLD, m, {mat}, direct_options());
  EXPECT_EQ(model.invalid_element(), "no element found invalid");
  // turn the cube inside out through x = 0.5: every element is inverted
  std::vector<Vec3d> u(m.X.size());
  for (size_t n = 0; n < m.X.size(); ++n) u[n] = Vec3d(1.0 - 2.0 * m.X[n].x(), 0.0, 0.0);
  model.set_displacement(u);
  EXPECT_FALSE(model.assemble(model.residual_vector(), nullptr));
  const std::string what = model.invalid_element();
  EXPECT_NE(what.find("of block 'cube' at ("), std::string::npos) << what;
}

// A mesh file with an inverted element, or a scene whose layers and mesh disagree, is refused when
// the scene is read, naming the file, the element or the names the mesh does have.
TEST(Scene, ArteryMeshFileCheckedAgainstTheScene) {
  const std::string data = ANGIO_SOLID_TEST_DATA;
  std::ifstream in(data + "/layered_tube_ascii.msh");
  std::string msh((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string tag = std::to_string(getpid()) + "_" + std::to_string(world_rank());
  const std::string dir = std::filesystem::temp_directory_path();
  // the first tet10 (type 11) entity block: swap the first two nodes of its first element
  size_t line = msh.find('\n', msh.find('\n', msh.find("$Elements")) + 1) + 1;  // the first block header
  for (;;) {
    std::istringstream header(msh.substr(line, msh.find('\n', line) - line));
    long dim = 0, entity = 0, type = 0, count = 0;
    ASSERT_TRUE(header >> dim >> entity >> type >> count);
    line = msh.find('\n', line) + 1;
    if (type == 11) break;
    for (long k = 0; k < count; ++k) line = msh.find('\n', line) + 1;
  }
  std::istringstream first(msh.substr(line, msh.find('\n', line) - line));
  std::vector<long> ids{std::istream_iterator<long>(first), std::istream_iterator<long>()};
  ASSERT_EQ(ids.size(), 11u);
  std::swap(ids[1], ids[2]);
  std::string swapped;
  for (long v : ids) swapped += std::to_string(v) + " ";
  std::string bad = msh;
  bad.replace(line, msh.find('\n', line) - line, swapped);
  const std::string good_msh = dir + "/angio_good_" + tag + ".msh", bad_msh = dir + "/angio_inverted_" + tag + ".msh";
  std::ofstream(good_msh) << msh;
  std::ofstream(bad_msh) << bad;
  auto scene = [&](const std::string& mesh, const std::string& layers) {
    const std::string path = dir + "/angio_mesh_scene_" + tag + ".yaml";
    std::ofstream(path) << "time: {end: 1.0, steps: 1}\n"
                           "load_curves: {ramp: [[0, 0], [1, 1]]}\n"
                           "artery:\n  mesh: {file: "
                        << mesh
                        << ", inner: inner, outer: outer, ends: [end0, end1]}\n"
                           "  layers:\n"
                        << layers << "  blood_pressure: {value: 0.01, curve: ramp}\n";
    return path;
  };
  const std::string two = "    media: {E: 0.1, nu: 0.45}\n    adventitia: {E: 0.01, nu: 0.45}\n";
  auto error = [&](const std::string& path) -> std::string {
    try {
      read_solid_scene(angio::scene::load_scene(path));
    } catch (const angio::scene::SceneError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error(scene(good_msh, two)), "");
  std::string w = error(scene(bad_msh, two));
  EXPECT_NE(w.find("artery.mesh.file"), std::string::npos) << w;
  EXPECT_NE(w.find(bad_msh), std::string::npos) << w;
  EXPECT_NE(w.find("inverted"), std::string::npos) << w;
  w = error(scene(good_msh, two + "    intima: {E: 0.1, nu: 0.45}\n"));
  EXPECT_NE(w.find("has no layer 'intima' (it has: media, adventitia)"), std::string::npos) << w;
  EXPECT_NE(w.find(good_msh), std::string::npos) << w;
  w = error(scene(good_msh, "    media: {E: 0.1, nu: 0.45}\n"));
  EXPECT_NE(w.find("missing 'adventitia'"), std::string::npos) << w;
  std::filesystem::remove(good_msh);
  std::filesystem::remove(bad_msh);
}
