// Idealized stenosis of the tube generator (mesh.hpp, TubeStenosis): the lumen follows the cosine
// bump r(z) = R_i (1 − s (1 + cos(2π (z − z_s)/L))/2) node for node (analytic), the innermost layer
// takes up the narrowing and the others keep their radii, and every hex8 keeps a positive volume.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "angio/solid/mesh.hpp"
#include "hex_volume.hpp"

using namespace angio::solid;
using angio::solid::test::hex_volume;

namespace {
TubeSpec stenosed(double severity) {
  TubeSpec t;
  t.part = "artery";
  t.surface_prefix = "artery_";
  t.length = 10.0;
  t.inner_radius = 1.5;
  t.layers = {{"plaque", 0.2, 3}, {"media", 0.3, 2}, {"adventitia", 0.3, 2}};
  t.n_circ = 16;
  t.n_axial = 40;
  t.stenosis = {severity, 6.0, 1.0};
  return t;
}
}  // namespace

TEST(TubeStenosis, LumenFollowsTheCosineBumpAndOuterLayersKeepTheirRadii) {
  const TubeSpec t = stenosed(0.7);
  const Mesh m = make_tube(t);
  double r_min = 1e9;
  for (int n : m.node_sets.at("artery_inner")) {
    const Vec3d x = m.X[n];
    const double r = std::hypot(x.x(), x.y()), z = x.z();
    EXPECT_NEAR(r, t.stenosis.lumen_radius(1.5, z), 1e-12);
    const double d = z - 1.0;
    const double expected =
        std::abs(d) <= 3.0 ? 1.5 * (1.0 - 0.35 * (1.0 + std::cos(std::numbers::pi * d / 3.0))) : 1.5;
    EXPECT_NEAR(r, expected, 1e-12) << "z = " << z;
    r_min = std::min(r_min, r);
  }
  EXPECT_NEAR(r_min, 1.5 * 0.3, 1e-12);  // 70 % diameter stenosis at z = 1 (a node there: 10/40 spacing)
  for (int n : m.node_sets.at("artery_outer")) EXPECT_NEAR(std::hypot(m.X[n].x(), m.X[n].y()), 2.3, 1e-12);
  for (const auto& e : m.elements) EXPECT_GT(hex_volume(m, e), 0.0);
  EXPECT_EQ(t.stenosis.lumen_radius(1.5, -4.0), 1.5);
}

TEST(TubeStenosis, ZeroSeverityIsThePlainTube) {
  const Mesh m = make_tube(stenosed(0.0));
  // shells at the layers' even divisions from the inner radius: 1.5 + 0.2 j/3, then 0.15 apart
  const std::vector<double> shells{1.5, 1.5 + 0.2 / 3, 1.5 + 0.4 / 3, 1.7, 1.85, 2.0, 2.15, 2.3};
  for (const auto& x : m.X) {
    const double r = std::hypot(x.x(), x.y());
    double best = 1e9;
    for (double s : shells) best = std::min(best, std::abs(r - s));
    EXPECT_LT(best, 1e-12) << "r = " << r;
  }
}

TEST(TubeStenosis, SeverityOneOrNoLengthIsRefused) {
  TubeSpec t = stenosed(1.0);
  EXPECT_THROW(make_tube(t), std::runtime_error);
  t = stenosed(0.5);
  t.stenosis.length = 0.0;
  EXPECT_THROW(make_tube(t), std::runtime_error);
}
