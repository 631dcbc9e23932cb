// Measures a user reads from an artery (artery_measures.hpp), against exact values.
#include <random>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "angio/solid/artery_measures.hpp"

using namespace angio::solid;

namespace {
// Straight one-layer artery tube: inner radius 0.8 mm, wall 0.3 mm, centred at the origin along z.
Mesh artery_tube(double length, int n_radial, int n_circ, int n_axial) {
  TubeSpec t;
  t.part = "artery";
  t.surface_prefix = "artery_";
  t.length = length;
  t.inner_radius = 0.8;
  t.layers = {{"media", 0.3, n_radial}};
  t.n_circ = n_circ;
  t.n_axial = n_axial;
  return make_tube(t);
}
}  // namespace

// Exact: the volume-weighted quantile is the value at which the cumulative weight first reaches q.
TEST(ArteryMeasures, WeightedQuantile) {
  // values 1..100 with equal weights: the 99 % quantile is 99, the median 50
  std::vector<double> v, w;
  for (int i = 100; i >= 1; --i) {
    v.push_back(i);
    w.push_back(1.0);
  }
  EXPECT_EQ(weighted_quantile(v, w, 0.99), 99.0);
  EXPECT_EQ(weighted_quantile(v, w, 0.5), 50.0);
  EXPECT_EQ(weighted_quantile(v, w, 1.0), 100.0);
  // one huge value in a tiny element does not move the 99 % quantile (the reason to report it)
  v = {1.0, 2.0, 1000.0};
  w = {50.0, 49.5, 0.5};
  EXPECT_EQ(weighted_quantile(v, w, 0.99), 2.0);
  EXPECT_TRUE(std::isnan(weighted_quantile({}, {}, 0.99)));
}

// Exact: the endothelium nodes of a generated tube lie on circles, so every station measures 2 r_i;
// a rigid translation moves the centroids with it and changes no diameter, and a radial scaling of
// one ring changes only its station.
TEST(ArteryMeasures, LumenProfileOfATube) {
  const Mesh m = artery_tube(4.0, 1, 16, 8);
  const SurfaceSet* endo = m.surface("artery_inner");
  ASSERT_NE(endo, nullptr);
  std::vector<int> nodes;
  for (const auto& f : endo->faces)
    for (int a = 0; a < f.nn(); ++a) nodes.push_back(f.n[a]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  std::vector<double> s;
  for (int n : nodes) s.push_back(m.X[n](2));
  const LumenProfile lp(s, 100);
  ASSERT_EQ(lp.stations().size(), 9u);                   // the rings of the structured tube
  auto positions = [&](const std::vector<Vec3d>& all) {  // of the endothelium nodes, in their order
    std::vector<Vec3d> out;
    for (int n : nodes) out.push_back(all[n]);
    return out;
  };
  std::vector<Vec3d> x = positions(m.X);
  for (double d : lp.diameters(x)) EXPECT_NEAR(d, 1.6, 1e-12);
  // the centroids are the tube's axis points at the stations, and move with a rigid translation
  std::vector<Vec3d> c;
  lp.diameters(x, &c);
  ASSERT_EQ(c.size(), lp.stations().size());
  for (size_t k = 0; k < c.size(); ++k) EXPECT_LT((c[k] - Vec3d(0, 0, lp.stations()[k])).norm(), 1e-12);
  for (auto& p : x) p += Vec3d(0.3, -0.2, 1.0);
  for (double d : lp.diameters(x, &c)) EXPECT_NEAR(d, 1.6, 1e-12);
  for (size_t k = 0; k < c.size(); ++k) EXPECT_LT((c[k] - Vec3d(0.3, -0.2, 1.0 + lp.stations()[k])).norm(), 1e-12);
  std::vector<Vec3d> scaled = m.X;
  for (int n : nodes)
    if (std::abs(m.X[n](2)) < 1e-9) scaled[n].head<2>() *= 1.25;  // the middle station (z = 0)
  const auto d = lp.diameters(positions(scaled));
  for (size_t k = 0; k < d.size(); ++k)
    EXPECT_NEAR(d[k], std::abs(lp.stations()[k]) < 1e-9 ? 2.0 : 1.6, 1e-12) << "station " << lp.stations()[k];
  // fewer allowed stations than rings: equal bins
  const LumenProfile coarse(s, 4);
  EXPECT_EQ(coarse.stations().size(), 4u);
  // positions of another node list (the whole mesh's) are refused, not read out of order
  EXPECT_THROW(lp.diameters(m.X), std::invalid_argument);
}

// Consistency on an unstructured endothelium (tet10 patient arteries): 480 nodes evenly spread
// over a cylinder of radius 0.8 like a surface mesh's, but not on rings (jittered angles and
// stations). Bins of ~2 nodes (100 stations) would measure the distance of two points from their
// midpoint; stations of >= 8 nodes measured in their cross-section give the diameter to 3 %.
TEST(ArteryMeasures, LumenProfileOfAnUnstructuredSurface) {
  std::vector<Vec3d> x;
  std::vector<double> s;
  std::mt19937 gen(12345u);
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);
  for (int j = 0; j < 40; ++j) {
    const double offset = jitter(gen);
    for (int k = 0; k < 12; ++k) {
      const double th = 2.0 * std::numbers::pi * (k + offset + jitter(gen)) / 12.0, z = 0.25 * (j + jitter(gen));
      x.emplace_back(0.8 * std::cos(th), 0.8 * std::sin(th), z);
      s.push_back(z);
    }
  }
  const LumenProfile lp(s, 100);
  EXPECT_EQ(lp.stations().size(), 20u);  // 480 nodes / 24 per station
  for (double d : lp.diameters(x)) EXPECT_NEAR(d, 1.6, 0.03 * 1.6);
}

// Exact: fractions of a weighted set of gaps; +∞ (no wall within the search radius) is malapposed.
TEST(ArteryMeasures, Apposition) {
  const double inf = std::numeric_limits<double>::infinity();
  const auto a = apposition({-0.01, 0.05, 0.2, inf}, {1.0, 1.0, 2.0, 1.0}, 0.1);
  EXPECT_DOUBLE_EQ(a.length, 5.0);
  EXPECT_DOUBLE_EQ(a.malapposed_length, 3.0);
  EXPECT_DOUBLE_EQ(a.malapposed_fraction, 0.6);
  EXPECT_DOUBLE_EQ(a.max_gap, 0.2);
  EXPECT_DOUBLE_EQ(a.mean_gap, (-0.01 + 0.05 + 0.4) / 4.0);
}

// Exact: lumped nodal areas of a surface add up to its area (flat faces of the tube's end ring).
TEST(ArteryMeasures, NodalAreasSumToTheSurfaceArea) {
  const Mesh m = artery_tube(2.0, 2, 12, 2);
  const auto area = nodal_areas(m, *m.surface("artery_end0"));
  double sum = 0.0;
  for (double a : area) sum += a;
  // the end face is a ring of 12 plane trapezoids between r = 0.8 and 1.1: area 12 sin(π/12)cos(π/12)(1.1² − 0.8²)
  const double exact =
      12.0 * std::sin(std::numbers::pi / 12) * std::cos(std::numbers::pi / 12) * (1.1 * 1.1 - 0.8 * 0.8);
  EXPECT_NEAR(sum, exact, 1e-12);
}
