// Stent generator (paper §2.2: 8 crowns, crimped diameter 1.15 mm, strut length ≈ 1.52 mm,
// 3 elements per strut: 4 rings → 210 elements, 11 rings → 588), warping onto a curved
// centerline, and scene parsing / error messages.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "angio/beam/scene.hpp"
#include "angio/beam/stent_generator.hpp"

using namespace angio::beam;

namespace {

std::vector<double> strut_lengths(const StentMesh& m) {
  std::vector<double> len(m.num_struts + m.num_connectors, 0.0);
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const int g = m.element_kind[e] == 0 ? m.element_group[e] : m.num_struts + m.element_group[e];
    len[g] += (m.nodes[m.elements[e][1]] - m.nodes[m.elements[e][0]]).norm();
  }
  return len;
}

std::vector<Vec3> arc_centerline(double radius, double length, int n) {
  std::vector<Vec3> pts;
  for (int i = 0; i <= n; ++i) {
    const double a = length / radius * i / n;
    pts.emplace_back(radius * (1 - std::cos(a)), 0.3 * a, radius * std::sin(a));  // helix-like
  }
  return pts;
}

}  // namespace

// Element counts of the paper: 4 rings → 210, 11 rings → 588.
TEST(StentGenerator, PaperElementCounts) {
  StentParameters p;
  EXPECT_EQ(generate_corrugated_rings(p).elements.size(), 210u);
  p.rings = 11;
  const StentMesh m = generate_corrugated_rings(p);
  EXPECT_EQ(m.elements.size(), 588u);
  EXPECT_EQ(m.num_struts, 11 * 16);
  EXPECT_EQ(m.num_connectors, 10 * 2);
}

// Crimped diameter 1.15 mm (all nodes on the cylinder), strut length sqrt(1.5² + (π·1.15/16)²)
// ≈ 1.517 mm measured along the strut polyline (chords of the helical strut, within 0.1 %),
// stent length = rings × 1.5 mm, and every node used.
TEST(StentGenerator, CrimpedGeometry) {
  StentParameters p;
  const StentMesh m = generate_corrugated_rings(p);
  for (const auto& x : m.nodes) EXPECT_NEAR(std::hypot(x.x(), x.y()), 0.575, 1e-12);
  double zmin = 1e9, zmax = -1e9;
  for (const auto& x : m.nodes) {
    zmin = std::min(zmin, x.z());
    zmax = std::max(zmax, x.z());
  }
  EXPECT_NEAR(zmax - zmin, 6.0, 1e-12);
  const auto len = strut_lengths(m);
  const double expected = std::hypot(1.5, M_PI * 1.15 / 16);
  EXPECT_NEAR(expected, 1.517, 1e-3);
  for (int s = 0; s < m.num_struts; ++s) EXPECT_NEAR(len[s], expected, 1e-3 * expected);
  for (int c = 0; c < m.num_connectors; ++c) EXPECT_NEAR(len[m.num_struts + c], M_PI * 1.15 / 16, 1e-3);
  std::vector<int> used(m.nodes.size(), 0);
  for (const auto& e : m.elements) used[e[0]] = used[e[1]] = 1;
  for (int u : used) EXPECT_EQ(u, 1);
  EXPECT_EQ(m.fixation_nodes.size(), 4u);
}

// Warping onto a curved centerline keeps the centerline unstretched: the straight-stent axial
// coordinate equals the arc length, so the total strut length is preserved to second order
// (outer side stretched, inner side compressed by ±r/ρ); we require the mean strut length to
// stay within 0.5 % and each strut within r/ρ + 1 %, and the radial distance of every node from
// the centerline to stay 0.575 mm.
TEST(StentGenerator, WarpedStentKeepsStrutLengths) {
  StentParameters p;
  p.rings = 4;
  const double rho = 20.0;
  const auto cl = arc_centerline(rho, 10.0, 200);
  const StentMesh straight = generate_corrugated_rings(p);
  const StentMesh warped = generate_corrugated_rings(p, cl);
  ASSERT_EQ(straight.elements.size(), warped.elements.size());
  const auto a = strut_lengths(straight), b = strut_lengths(warped);
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
    EXPECT_NEAR(b[i] / a[i], 1.0, 0.575 / rho + 0.01);
  }
  EXPECT_NEAR(mb / ma, 1.0, 5e-3);
  // distance from the curved axis in the sense of the warp (to round-off)
  const angio::geometry::Centerline c(cl);
  for (const auto& x : warped.nodes) EXPECT_NEAR(c.closest(x).distance, 0.575, 1e-12);
}

// Rotation-minimizing frames: see tests/geometry/test_centerline.cpp (core/geometry).

// The shipped scenes parse; a bad value gives "file: key.path: expected …".
TEST(BeamScene, ShippedConfigsParse) {
  const std::string dir = std::string(ANGIO_SOURCE_DIR) + "/configs/";
  BeamScene s = load_beam_scene(dir + "beam_stent_radial_expansion.yaml");
  EXPECT_EQ(s.model->num_elements(), 210);
  EXPECT_TRUE(s.model->element_section(0).plastic);
  EXPECT_NEAR(s.model->diameter(), 1.15, 1e-12);
  BeamScene c = load_beam_scene(dir + "beam_cantilever_rollup.yaml");
  EXPECT_EQ(c.model->num_elements(), 20);
  BeamScene k = load_beam_scene(dir + "beam_stent_curved.yaml");
  EXPECT_EQ(k.model->num_elements(), 588);
  EXPECT_NEAR(k.model->diameter(), 1.15, 2e-3);  // radial distance from the centerline polyline
}

namespace {
// Loads a scene given as text; returns the SceneError message (fails the test if none).
std::string scene_error(const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / "beam_bad_scene.yaml";
  std::ofstream(path) << text;
  std::string what;
  try {
    load_beam_scene(path.string());
    ADD_FAILURE() << "expected SceneError";
  } catch (const angio::scene::SceneError& e) {
    what = e.what();
  }
  std::filesystem::remove(path);
  return what;
}
}  // namespace

TEST(BeamScene, BadInputNamesKeyPath) {
  const std::string w = scene_error(
      "time: {end: 1, steps: 2}\nstent:\n  material: {E: -5, nu: 0.3}\n  section: {radius: 0.06}\n"
      "  lines: [{from: [0,0,0], to: [1,0,0], elements: 2}]\n");
  EXPECT_NE(w.find("stent.material.E"), std::string::npos) << w;
  EXPECT_NE(w.find("beam_bad_scene.yaml"), std::string::npos) << w;
  const std::string g = scene_error(
      "time: {end: 1, steps: 2}\nstent:\n  material: {E: 5, nu: 0.3}\n  section: {radius: 0.06}\n"
      "  generator: {type: corrugated_rings, ringz: 3}\n");
  EXPECT_NE(g.find("ringz"), std::string::npos) << g;
  // radial fixation of a node on the device axis (default axis: the z axis)
  const std::string f = scene_error(
      "time: {end: 1, steps: 2}\nstent:\n  material: {E: 5, nu: 0.3}\n  section: {radius: 0.06}\n"
      "  lines: [{from: [0,0,0], to: [1,0,1], elements: 2}]\n  fixation: {radial: [0]}\n");
  EXPECT_NE(f.find("stent.fixation.radial"), std::string::npos) << f;
  EXPECT_NE(f.find("off the device axis"), std::string::npos) << f;
}

// A centerline read from a text file ("x y z" or "x,y,z" per line, '#' comments) gives the
// same warped stent as the same points given inline.
TEST(StentGenerator, CenterlineFromFile) {
  const auto path = std::filesystem::temp_directory_path() / "beam_centerline_test.txt";
  const auto pts = arc_centerline(25.0, 9.0, 60);
  {
    std::ofstream f(path);
    f << "# x y z (mm)\n";
    f.precision(17);
    for (size_t i = 0; i < pts.size(); ++i)
      f << pts[i].x() << (i % 2 ? ", " : " ") << pts[i].y() << " " << pts[i].z() << "\n";
  }
  const auto read = angio::geometry::read_centerline_points(path.string());
  ASSERT_EQ(read.size(), pts.size());
  const StentMesh a = generate_corrugated_rings(StentParameters{}, pts);
  const StentMesh b = generate_corrugated_rings(StentParameters{}, read);
  for (size_t n = 0; n < a.nodes.size(); ++n) EXPECT_LT((a.nodes[n] - b.nodes[n]).norm(), 1e-12);
  std::filesystem::remove(path);
  EXPECT_THROW(angio::geometry::read_centerline_points("/nonexistent/centerline.txt"), std::runtime_error);
}
