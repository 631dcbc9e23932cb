// Resolution where the stresses are read in the tube generator (mesh.hpp): radial grading of a layer
// (progression) and a finer axial window. Exact checks: the graded shell radii are the geometric
// series, the window's spacing is length/n_axial/factor, the tube's surfaces and total volume are the
// uniform tube's, every hex8 has a positive volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "angio/solid/mesh.hpp"
#include "hex_volume.hpp"

using namespace angio::solid;
using angio::solid::test::hex_volume;

namespace {
TubeSpec tube() {
  TubeSpec t;
  t.part = "artery";
  t.surface_prefix = "artery_";
  t.length = 11.0;
  t.inner_radius = 0.8;
  t.layers = {{"media", 0.3, 3, 1.5}, {"adventitia", 0.3, 2, 1.0}};
  t.n_circ = 24;
  t.n_axial = 22;
  return t;
}
double total_volume(const Mesh& m) {
  double v = 0.0;
  for (const auto& e : m.elements) {
    const double ve = hex_volume(m, e);
    EXPECT_GT(ve, 0.0);
    v += ve;
  }
  return v;
}
}  // namespace

// The media's three shells: thicknesses t0, 1.5 t0, 2.25 t0 with t0 = 0.3 / (1 + 1.5 + 2.25).
TEST(TubeRefinement, RadialProgressionIsTheGeometricSeries) {
  const Mesh m = make_tube(tube());
  std::set<double> radii;
  for (const auto& x : m.X) radii.insert(std::round(std::hypot(x.x(), x.y()) * 1e12) / 1e12);
  ASSERT_EQ(radii.size(), 6u);  // 3 + 2 elements through the wall
  const std::vector<double> r(radii.begin(), radii.end());
  const double t0 = 0.3 / (1.0 + 1.5 + 2.25);
  EXPECT_NEAR(r[1] - r[0], t0, 1e-12);
  EXPECT_NEAR(r[2] - r[1], 1.5 * t0, 1e-12);
  EXPECT_NEAR(r[3] - r[2], 2.25 * t0, 1e-12);
  EXPECT_NEAR(r[3], 1.1, 1e-12);  // the layer keeps its thickness
  EXPECT_NEAR(r[4] - r[3], 0.15, 1e-12);
  EXPECT_NEAR(r[5], 1.4, 1e-12);
}

TEST(TubeRefinement, AxialWindowSpacingAndCounts) {
  TubeAxialRefinement w{-3.0, 3.0, 2.0};
  const auto z = w.stations(11.0, 22);  // h = 0.5: 5 elements of 0.5 on each side, 24 of 0.25 in the window
  ASSERT_EQ(z.size(), 5u + 24u + 5u + 1u);
  EXPECT_EQ(z.front(), 0.0);
  EXPECT_EQ(z.back(), 11.0);
  for (size_t k = 0; k + 1 < z.size(); ++k) {
    const double mid = 0.5 * (z[k] + z[k + 1]) - 5.5;
    EXPECT_NEAR(z[k + 1] - z[k], std::abs(mid) < 3.0 ? 0.25 : 0.5, 1e-12) << "k = " << k;
  }
  // a window at the end: no empty part, counts rounded
  const auto e = TubeAxialRefinement{1.0, 5.5, 3.0}.stations(11.0, 10);
  EXPECT_EQ(e.size(), size_t(std::lround(6.5 / 1.1)) + size_t(std::lround(4.5 / 1.1 * 3.0)) + 1);
  EXPECT_TRUE(std::is_sorted(e.begin(), e.end()));
  EXPECT_EQ(e.back(), 11.0);
  // factor 1: the uniform stations
  const auto u = TubeAxialRefinement{}.stations(11.0, 22);
  ASSERT_EQ(u.size(), 23u);
  for (size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], 0.5 * k, 1e-12);
  EXPECT_THROW(TubeAxialRefinement({2.0, 1.0, 2.0}).stations(11.0, 22), std::runtime_error);
  EXPECT_THROW(TubeAxialRefinement({-6.0, 1.0, 2.0}).stations(11.0, 22), std::runtime_error);
}

// Grading and the window move nodes inside the wall only: the lumen, the outer surface and the
// total volume (of the polygonal tube) are the uniform tube's.
TEST(TubeRefinement, SameTubeAsTheUniformMesh) {
  TubeSpec graded = tube();
  graded.axial_refinement = {-3.0, 3.0, 2.0};
  TubeSpec uniform = tube();
  for (auto& l : uniform.layers) l.progression = 1.0;
  const Mesh g = make_tube(graded), u = make_tube(uniform);
  EXPECT_NEAR(total_volume(g), total_volume(u), 1e-12 * total_volume(u));
  EXPECT_EQ(g.elements.size(), size_t(24 * 5 * 34));
  for (int n : g.node_sets.at("artery_inner")) EXPECT_NEAR(std::hypot(g.X[n].x(), g.X[n].y()), 0.8, 1e-12);
  for (int n : g.node_sets.at("artery_outer")) EXPECT_NEAR(std::hypot(g.X[n].x(), g.X[n].y()), 1.4, 1e-12);
}

// With a stenosis the innermost layer keeps its graded fractions between the narrowed lumen and its
// outer radius.
TEST(TubeRefinement, ProgressionWithStenosis) {
  TubeSpec t = tube();
  t.stenosis = {0.5, 6.0, 0.0};
  const Mesh m = make_tube(t);
  const double t0 = 1.0 / (1.0 + 1.5 + 2.25);
  for (size_t k = 0; k < m.X.size(); k += size_t(t.n_circ) * 6) {  // the first node of each axial ring
    const double z = m.X[k].z(), rl = t.stenosis.lumen_radius(0.8, z), span = 1.1 - rl;
    EXPECT_NEAR(std::hypot(m.X[k].x(), m.X[k].y()), rl, 1e-12);
    EXPECT_NEAR(std::hypot(m.X[k + t.n_circ].x(), m.X[k + t.n_circ].y()), rl + span * t0, 1e-12) << "z = " << z;
  }
  for (const auto& e : m.elements) EXPECT_GT(hex_volume(m, e), 0.0);
}
