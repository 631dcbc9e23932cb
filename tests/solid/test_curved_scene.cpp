// The curved free-expansion scene's solid part (configs/curved_free_expansion.yaml, paper §3.2):
// the balloon warped onto centerlines/curved_arc_r15.txt, its diameter summary measured from the
// curved centerline, and the scene errors for a curved tube. Each test states what it compares
// against.
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "angio/solid/participant.hpp"
#include "angio/solid/scene.hpp"

using namespace angio::solid;

namespace {
const std::string kConfigs = ANGIO_CONFIGS_DIR;

// Per-process file name: the np1 and np2 variants of this test run at the same time under ctest -j.
std::string write_scene(const std::string& name, const std::string& mesh_line) {
  const auto path = std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
  std::ofstream f(path);
  f << "time: {end: 1.0, steps: 1}\nballoon:\n  mesh: " << mesh_line
    << "\n  material: {E: 17.0, nu: 0.0}\n  pressure: 0.1\n";
  return path.string();
}

std::string scene_error(const std::string& path) {
  try {
    read_solid_scene(angio::scene::load_scene(path));
  } catch (const angio::scene::SceneError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// Compared with the scene's numbers: 22 x 126 = 2772 hex8 (paper 2765), 1 GPa = 1000 N/mm^3 springs on both
// ends, diameter stations at arc lengths L/2 and start + 0.75 / start + 18 − 0.75 of the centred
// balloon (start = (24.025 − 18)/2), and the reference outer diameter 0.98 mm measured from the
// curved centerline at all three stations (to round-off: the nodes sit exactly at 0.49 mm).
TEST(CurvedScene, BalloonOnTheCenterline) {
  SolidScene sc = read_solid_scene(angio::scene::load_scene(kConfigs + "/curved_free_expansion.yaml"));
  EXPECT_EQ(sc.mesh.elements.size(), 2772u);
  ASSERT_EQ(sc.springs.size(), 2u);
  EXPECT_DOUBLE_EQ(sc.springs[0].stiffness, 1000.0);
  ASSERT_TRUE(sc.balloon_diameter.has_value());
  const auto& d = *sc.balloon_diameter;
  ASSERT_TRUE(d.centerline.has_value());
  const double L = d.centerline->length(), start = 0.5 * (L - 18.0);
  EXPECT_NEAR(L, 24.025, 1e-3);
  EXPECT_NEAR(d.s_mid, 0.5 * L, 1e-9);
  EXPECT_NEAR(d.s_end0, start + 0.75, 1e-9);
  EXPECT_NEAR(d.s_end1, start + 18.0 - 0.75, 1e-9);
  SolidRunner runner(PETSC_COMM_WORLD, sc, "");
  const auto& h0 = runner.history().at(0);
  EXPECT_NEAR(h0.d_mid, 0.98, 1e-10);
  EXPECT_NEAR(h0.d_end0, 0.98, 1e-10);
  EXPECT_NEAR(h0.d_end1, 0.98, 1e-10);
}

// Bad curved-tube input stops with "file: key.path: expected ..." naming the key (compared with
// the key paths balloon.mesh.length / .start / .center / .centerline.file).
TEST(CurvedScene, ErrorsNameFileAndKey) {
  const std::string cl = kConfigs + "/centerlines/curved_arc_r15.txt";
  const std::string base = "{generator: tube, outer_diameter: 0.98, wall: 0.04, n_circ: 8, n_axial: 4, ";
  struct Case {
    std::string mesh, key, also;
  } cases[] = {
      {base + "length: 30.0, centerline: {file: " + cl + "}}", "balloon.mesh.length", "curved_arc_r15.txt"},
      {base + "length: 18.0, start: 10.0, centerline: {file: " + cl + "}}", "balloon.mesh.start", "24.0"},
      {base + "length: 18.0, center: [0, 0, 0], centerline: {file: " + cl + "}}", "balloon.mesh.center", "centerline"},
      {base + "length: 18.0, start: 1.0}", "balloon.mesh.start", "centerline"},
      {base + "length: 18.0, centerline: {file: nowhere.txt}}", "balloon.mesh.centerline.file", "nowhere.txt"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const std::string path = write_scene("curved_scene_error_" + std::to_string(i++) + ".yaml", c.mesh);
    const std::string w = scene_error(path);
    EXPECT_NE(w.find(path), std::string::npos) << w;
    EXPECT_NE(w.find(c.key), std::string::npos) << w;
    EXPECT_NE(w.find(c.also), std::string::npos) << w;
    std::filesystem::remove(path);
  }
}

// artery.tissue_support: springs of the given stiffness on the artery's outer surface, besides its
// end springs (compared with the scene's numbers); absent, none.
TEST(CurvedScene, TissueSupportSpringsOnTheOuterSurface) {
  const auto path = std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_tissue_support.yaml");
  auto scene_with = [&](const std::string& support) {
    std::ofstream f(path);
    f << "time: {end: 1.0, steps: 1}\nartery:\n  mesh: {generator: tube, length: 4.0, outer_diameter: 2.8, n_circ: 8, "
         "n_axial: 4, layers: [{name: media, thickness: 0.3, n_radial: 1}]}\n  layers: {media: {E: 0.1566, nu: 0.45}}\n"
         "  blood_pressure: 0.01133\n  end_springs: 1000.0\n"
      << support;
    f.close();
    return read_solid_scene(angio::scene::load_scene(path.string()));
  };
  const SolidScene with = scene_with("  tissue_support: 0.005\n");
  ASSERT_EQ(with.springs.size(), 3u);
  EXPECT_EQ(with.springs[2].surface, "artery_outer");
  EXPECT_DOUBLE_EQ(with.springs[2].stiffness, 0.005);
  ASSERT_NE(with.mesh.surface("artery_outer"), nullptr);
  EXPECT_FALSE(with.mesh.surface("artery_outer")->faces.empty());
  EXPECT_EQ(scene_with("").springs.size(), 2u);
  std::filesystem::remove(path);
}
