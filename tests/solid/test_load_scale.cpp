// The force scale of pressure loads (load_scale.hpp), against the exact consistent nodal forces of a
// uniform pressure on flat faces.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "angio/solid/load_scale.hpp"

using namespace angio::solid;

namespace {
Mesh one_face(FaceType type, const std::vector<Vec3d>& X) {
  Mesh m;
  m.X = X;
  SurfaceSet s{"lid", {}};
  Face f;
  f.type = type;
  for (size_t a = 0; a < X.size(); ++a) f.n[a] = int(a);
  s.faces.push_back(f);
  m.surfaces.push_back(s);
  return m;
}
}  // namespace

// Exact: bilinear quad, uniform p on area A: each node carries p A / 4, so ||f|| = p A / 2.
TEST(LoadScale, QuadFaceUnderUniformPressure) {
  const Mesh m = one_face(FaceType::Quad4, {{0, 0, 0}, {2, 0, 0}, {2, 3, 0}, {0, 3, 0}});
  EXPECT_NEAR(pressure_load_norm(m, {{"lid", 0.5}}), 0.5 * 6.0 / 2.0, 1e-12);
  // linear in the pressure, blind to its sign
  EXPECT_NEAR(pressure_load_norm(m, {{"lid", -1.5}}), 1.5 * 6.0 / 2.0, 1e-12);
  // two pressures on the same face add before the norm is taken
  EXPECT_NEAR(pressure_load_norm(m, {{"lid", 0.5}, {"lid", 0.25}}), 0.75 * 6.0 / 2.0, 1e-12);
}

// Exact: quadratic triangle, uniform p on area A: the corners carry nothing, each mid-side node
// p A / 3, so ||f|| = p A / sqrt(3).
TEST(LoadScale, QuadraticTriangleUnderUniformPressure) {
  const Mesh m = one_face(FaceType::Tri6, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_NEAR(pressure_load_norm(m, {{"lid", 1.0}}), 2.0 / std::sqrt(3.0), 1e-12);
}

TEST(LoadScale, UnknownSurfaceIsAnError) {
  const Mesh m = one_face(FaceType::Quad4, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  EXPECT_THROW(pressure_load_norm(m, {{"lumen", 1.0}}), std::invalid_argument);
  EXPECT_EQ(pressure_load_norm(m, {}), 0.0);
}
