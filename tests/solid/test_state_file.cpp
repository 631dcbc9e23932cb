// Solid state files (state_file.hpp): a run continued from the state file of its first half ends
// where the uninterrupted run ends (consistency: the same committed displacement, viscous history and
// extrapolation base, so the same equilibria to round-off); a state lands on the parts named and only
// on the mesh it came from, and every mismatch is a scene error naming the key; the file written by
// all ranks together holds every row where the mesh order puts it (exact).
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "angio/common/h5_io.hpp"
#include "angio/participant/standalone.hpp"
#include "angio/solid/participant.hpp"
#include "angio/solid/scene.hpp"
#include "angio/solid/state_file.hpp"
#include "mpi_test.hpp"

using namespace angio::solid;
using angio_test::world_rank;
using angio_test::world_size;

namespace {

// A small two-layer artery with a viscous media (eqs. B.5–B.8): pressure ramped to t = 0.5 s, then
// held (the media relaxes: the viscous history matters after the restart); exact Newton and the
// extrapolated first iterate (the commit before the last matters too).
const char* kArtery = R"(
time: {start: 0.0, end: 1.0, steps: 8}
load_curves:
  p: [[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]]
output: {every: 2}
BALLOON
artery:
  mesh:
    generator: tube
    length: 2.0
    outer_diameter: 2.8
    n_circ: NCIRC
    n_axial: 4
    layers:
      - {name: media, thickness: 0.3, n_radial: 1}
      - {name: adventitia, thickness: 0.3, n_radial: 1}
  layers:
    media: {E: 0.1566, nu: 0.45, fibers: [{k1: 0.00064, k2: 3.54, angle: 0, pair: true}], viscous: {tau: 0.2, beta: 0.5}}
    adventitia: {E: 0.01566, nu: 0.45, fibers: [{k1: 0.0051, k2: 15.4, angle: 40, pair: true}]}
  blood_pressure: {value: 0.035, curve: p}
  end_springs: 1000.0
  fixed: [{surface: end0, components: [z]}]
solid:
  petsc_options: "-ksp_type preonly -pc_type lu"
  newton: {rtol: 1.0e-12, atol: 1.0e-12, continuation: 0, prediction: extrapolate}
  INITIAL
)";

const char* kBalloon = R"(balloon:
  mesh: {generator: tube, length: 1.6, outer_diameter: 0.98, wall: 0.04, n_circ: 12, n_axial: 4, center: [0, 0, 0]}
  material: {E: 17.0, nu: 0.3}
  pressure: {value: 0.01, curve: p}
  end_springs: 100.0)";

std::string dir_of(const std::string& name) {
  // per rank count: the np1 and np2 test runs may run concurrently
  return (std::filesystem::current_path() / ("state_file_test_np" + std::to_string(world_size()) + "/" + name))
      .string();
}

// Writes the scene (rank 0) and returns its path; `time` replaces the time line, `initial` the
// solid.initial_state entry.
std::string scene_file(const std::string& name, const std::string& time, const std::string& initial,
                       bool balloon = false, int n_circ = 12) {
  std::string t = kArtery;
  if (!time.empty()) t = std::regex_replace(t, std::regex("time: \\{[^}]*\\}"), time);
  t = std::regex_replace(t, std::regex("INITIAL"), initial);
  t = std::regex_replace(t, std::regex("BALLOON"), balloon ? kBalloon : "");
  t = std::regex_replace(t, std::regex("NCIRC"), std::to_string(n_circ));
  const std::string dir = dir_of("scenes");
  const std::string path = dir + "/" + name + ".yaml";
  if (world_rank() == 0) {
    std::filesystem::create_directories(dir);
    std::ofstream(path) << t;
  }
  MPI_Barrier(PETSC_COMM_WORLD);
  return path;
}

SolidScene read(const std::string& path) { return read_solid_scene(angio::scene::load_scene(path)); }

std::vector<Vec3d> run(const std::string& scene, const std::string& run_dir) {
  SolidScene sc = read(scene);
  const auto time = sc.time;
  SolidRunner runner(PETSC_COMM_WORLD, std::move(sc), run_dir);
  EXPECT_EQ(angio::participant::run_standalone(runner, time), 0);
  return runner.model().gather_displacement();
}

double max_difference(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b) {
  double d = 0.0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

// A table of a state file read whole: the tests' own reading of what the solver reads in chunks.
template <int N>
std::vector<Eigen::Matrix<double, N, 1>> table(const std::string& path, const std::string& dataset) {
  const angio::h5::Reader r{path};
  const angio::h5::H5Id f(angio::h5::open_for_reading(r), H5Fclose);
  return r.rows<N>(f, dataset);
}
std::vector<int> viscous_points(const std::string& path, const std::string& part) {
  const angio::h5::Reader r{path};
  const angio::h5::H5Id f(angio::h5::open_for_reading(r), H5Fclose);
  hsize_t rows = 0;
  return r.dataset<int>(f, "parts/" + part + "/viscous_points", H5T_NATIVE_INT, 1, rows);
}

// A copy of a state file with the artery's viscous overstresses Q set to zero (a fresh viscous branch).
std::string without_history(const std::string& state) {
  const std::string copy = dir_of("no_history_state.h5");
  if (world_rank() == 0) {
    std::filesystem::copy_file(state, copy, std::filesystem::copy_options::overwrite_existing);
    const angio::h5::H5Id f(H5Fopen(copy.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    const angio::h5::H5Id ds(H5Dopen2(f, "parts/artery/viscous_Q", H5P_DEFAULT), H5Dclose);
    const angio::h5::H5Id space(H5Dget_space(ds), H5Sclose);
    const std::vector<double> zeros(std::size_t(H5Sget_simple_extent_npoints(space)), 0.0);
    EXPECT_GE(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data()), 0);
  }
  MPI_Barrier(PETSC_COMM_WORLD);
  return copy;
}

// The first half's state, written once per test process.
const std::string& first_half_state() {
  static std::string state;
  if (state.empty()) {
    run(scene_file("first_half", "time: {start: 0.0, end: 0.5, steps: 4}", ""), dir_of("first_half"));
    state = dir_of("first_half") + "/solid/state.h5";
  }
  return state;
}

std::string initial(const std::string& parts = "") {
  return "initial_state: {file: " + first_half_state() + (parts.empty() ? "" : ", parts: " + parts) + "}";
}

}  // namespace

TEST(StateFile, ContinuedRunEndsWhereTheUninterruptedRunEnds) {
  const auto whole = run(scene_file("whole", "", ""), dir_of("whole"));
  const std::string& state_path = first_half_state();
  const StateFile state = read_state_file(state_path);
  EXPECT_NEAR(state.time, 0.5, 1e-15);
  ASSERT_EQ(state.parts.size(), 1u);
  EXPECT_EQ(state.parts[0].name, "artery");
  EXPECT_TRUE(state.has_before);  // prediction: extrapolate keeps the commit before
  EXPECT_NEAR(state.before_time, 0.375, 1e-15);
  double q = 0.0;
  for (const auto& Q : table<6>(state_path, "parts/artery/viscous_Q")) q = std::max(q, Q.norm());
  EXPECT_GT(q, 1e-4);  // the media's overstress at the end of the ramp (MPa): the history is not trivial

  const auto continued =
      run(scene_file("second_half", "time: {start: 0.5, end: 1.0, steps: 4}", initial()), dir_of("second_half"));
  double umax = 0.0;
  for (const auto& u : whole) umax = std::max(umax, u.norm());
  const double diff = max_difference(whole, continued);
  if (world_rank() == 0) std::printf("max |u| at t = 1: %.6f mm, continued - uninterrupted: %.3e mm\n", umax, diff);
  EXPECT_GT(umax, 0.05);
  EXPECT_LT(diff, 1e-10 * umax);

  // the same continuation with the history dropped (a fresh viscous branch) ends elsewhere: the
  // check above sees the history
  SolidScene sc = read(scene_file("second_half_fresh", "time: {start: 0.5, end: 1.0, steps: 4}",
                                  "initial_state: {file: " + without_history(state_path) + "}"));
  const auto time = sc.time;
  SolidRunner fresh(PETSC_COMM_WORLD, std::move(sc), "");
  ASSERT_EQ(angio::participant::run_standalone(fresh, time), 0);
  const std::vector<Vec3d> uf = fresh.model().gather_displacement();
  EXPECT_GT(max_difference(whole, uf), 1e3 * diff + 1e-8);
}

TEST(StateFile, PartsLandOnTheirNodesOthersStartUndeformed) {
  // the artery of the state under a new balloon (the next phase of a procedure)
  SolidScene sc = read(scene_file("with_balloon", "time: {start: 0.5, end: 1.0, steps: 1}", initial("[artery]"), true));
  const auto artery = table<3>(sc.initial_state->path, "parts/artery/displacement");
  SolidRunner runner(PETSC_COMM_WORLD, std::move(sc), "");
  const Mesh& mesh = runner.model().mesh();
  const auto nodes = part_nodes(mesh, "artery");
  ASSERT_EQ(nodes.size(), artery.size());
  double diff = 0.0, balloon = 0.0;
  const std::vector<Vec3d> u = runner.model().gather_displacement();
  for (size_t i = 0; i < nodes.size(); ++i) diff = std::max(diff, (u[nodes[i]] - artery[i]).norm());
  for (int n : part_nodes(mesh, "balloon")) balloon = std::max(balloon, u[n].norm());
  EXPECT_EQ(diff, 0.0);
  EXPECT_EQ(balloon, 0.0);
  EXPECT_GT(artery[0].norm(), 0.0);
}

TEST(StateFile, MismatchesAreSceneErrorsNamingTheKey) {
  auto message = [](const std::string& path) {
    try {
      read(path);
    } catch (const angio::scene::SceneError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string t = "time: {start: 0.5, end: 1.0, steps: 1}";
  EXPECT_NE(message(scene_file("other_mesh", t, initial(), false, 16))
                .find("solid.initial_state.file: expected parts that fit this scene's mesh"),
            std::string::npos);
  EXPECT_NE(message(scene_file("other_mesh", t, initial(), false, 16)).find("a different mesh"), std::string::npos);
  EXPECT_NE(message(scene_file("no_part", t, initial("[balloon]"), true)).find("has no part 'balloon'"),
            std::string::npos);
  EXPECT_NE(message(scene_file("twice", t, initial("[artery, artery]"))).find("each part once"), std::string::npos);
  EXPECT_NE(message(scene_file("time", "time: {start: 0.25, end: 1.0, steps: 1}", initial())).find("time.start"),
            std::string::npos);
  EXPECT_NE(message(scene_file("missing", t, "initial_state: {file: no_such_state.h5}")).find("no such file"),
            std::string::npos);
  EXPECT_NE(message(scene_file("not_hdf5", t, "initial_state: {file: not_hdf5.yaml}")).find("not an HDF5 file"),
            std::string::npos);
}

// Exact: the file holds each part's nodes in ascending mesh order (reference coordinates, committed
// displacement, the commit before) and each element's viscous history in ascending element order,
// whatever the ranks that wrote it (each rank writes the block of rows it was sent, file_blocks.hpp):
// a prescribed state written on this test's 1 or 2 ranks reads back bit for bit.
TEST(StateFile, WrittenByAllRanksInTheMeshOrder) {
  SolidScene sc = read(scene_file("layout", "", "", true));  // two parts, a viscous media
  const Mesh mesh = sc.mesh;
  const std::vector<LayerMaterial> materials = sc.materials;
  SolidModel model(PETSC_COMM_WORLD, std::move(sc.mesh), sc.materials, sc.options);
  auto field = [&](double s) {  // a displacement with nothing in common between nodes
    std::vector<Vec3d> u(mesh.X.size());
    for (size_t n = 0; n < u.size(); ++n)
      u[n] = s * Vec3d(std::sin(mesh.X[n](0)), mesh.X[n](1) * mesh.X[n](2), 1e-3 * double(n));
    return u;
  };
  model.start_from(0.75, field(2.0), field(1.0), 0.5);  // no Dirichlet conditions: the model alone
  auto history = [](int e, int g) {                     // element e's Gauss point g
    Vec6 q;
    for (int k = 0; k < 6; ++k) q(k) = double(e) + 0.1 * g + 0.01 * k;
    return q;
  };
  const auto& le = model.local_elements();
  for (size_t i = 0; i < le.size(); ++i) {
    const auto v = model.viscous_state(i);
    for (int g = 0; g < v.points; ++g) {
      v.Q[g] = history(le[i], g);
      v.Sv[g] = -history(le[i], g);
    }
  }
  const std::string path = dir_of("layout_state.h5");
  write_state_file(model, path, 7);
  const StateFile s = read_state_file(path);
  EXPECT_EQ(s.time, 0.75);
  EXPECT_EQ(s.step, 7);
  ASSERT_TRUE(s.has_before);
  EXPECT_EQ(s.before_time, 0.5);
  ASSERT_EQ(s.parts.size(), 2u);
  const std::vector<Vec3d> u = field(2.0), before = field(1.0);
  for (const std::string name : {"artery", "balloon"}) {
    const PartState* p = s.part(name);
    ASSERT_NE(p, nullptr) << name;
    const auto nodes = part_nodes(mesh, name);
    ASSERT_EQ(p->nodes, long(nodes.size())) << name;
    const auto X = table<3>(path, "parts/" + name + "/coordinates");
    const auto un = table<3>(path, "parts/" + name + "/displacement");
    const auto ub = table<3>(path, "parts/" + name + "/displacement_before");
    ASSERT_EQ(X.size(), nodes.size()) << name;
    ASSERT_EQ(un.size(), nodes.size()) << name;
    ASSERT_EQ(ub.size(), nodes.size()) << name;
    double d = 0.0;
    for (size_t i = 0; i < nodes.size(); ++i)
      d = std::max(
          {d, (X[i] - mesh.X[nodes[i]]).norm(), (un[i] - u[nodes[i]]).norm(), (ub[i] - before[nodes[i]]).norm()});
    EXPECT_EQ(d, 0.0) << name;
    const auto elems = part_elements(mesh, name);
    const auto points = viscous_points(path, name);
    const auto Q = table<6>(path, "parts/" + name + "/viscous_Q");
    const auto Sv = table<6>(path, "parts/" + name + "/viscous_Sv");
    ASSERT_EQ(points.size(), elems.size()) << name;
    ASSERT_EQ(p->points, long(Q.size())) << name;
    size_t row = 0, with_history = 0;
    double dq = 0.0;
    for (size_t k = 0; k < elems.size(); ++k) {
      const auto& el = mesh.elements[elems[k]];
      const int expected = materials[el.block].viscous ? int(volume_rule(el.type).size()) : 0;
      EXPECT_EQ(points[k], expected) << name << " element " << elems[k];
      with_history += expected > 0;
      for (int g = 0; g < points[k]; ++g, ++row) {
        ASSERT_LT(row, Q.size());
        dq = std::max({dq, (Q[row] - history(elems[k], g)).norm(), (Sv[row] + history(elems[k], g)).norm()});
      }
    }
    EXPECT_EQ(row, Q.size()) << name;
    EXPECT_EQ(dq, 0.0) << name;
    EXPECT_EQ(with_history > 0, name == "artery");  // the media's elements, not the balloon's
  }
  // the state read back onto the model (its rows, chunk by chunk), and a file replaced between the
  // check and the reading (a run that still writes it) refused on every rank
  apply_state(model, s, {"artery", "balloon"});
  double back = 0.0;
  for (size_t n = 0; n < mesh.X.size(); ++n)
    if (model.holds(int(n))) back = std::max(back, (model.committed_displacement(int(n)) - u[n]).norm());
  EXPECT_EQ(back, 0.0);
  write_state_file(model, path, 8);
  EXPECT_THROW(apply_state(model, s, {"artery"}), StateFileError);
}
