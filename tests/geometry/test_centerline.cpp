// Centerline of a curved device (core/geometry, paper §2.4: warp without stretching the
// centerline, minimal twist). Each test names what it compares against.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "angio/geometry/centerline.hpp"
#include "angio/geometry/centerline_scene.hpp"

using angio::geometry::Centerline;
using angio::geometry::Vec3;

namespace {

constexpr double pi = std::numbers::pi;

// Circular arc of radius rho in the x–z plane starting at the origin along +z (planar).
std::vector<Vec3> planar_arc(double rho, double length, int n) {
  std::vector<Vec3> p;
  for (int i = 0; i <= n; ++i) {
    const double a = length / rho * i / n;
    p.emplace_back(rho * (1 - std::cos(a)), 0.0, rho * std::sin(a));
  }
  return p;
}

// Helix (a cos t, a sin t, b t): curvature a/c², torsion b/c², c = sqrt(a² + b²).
std::vector<Vec3> helix(double a, double b, double tmax, int n) {
  std::vector<Vec3> p;
  for (int i = 0; i <= n; ++i) {
    const double t = tmax * i / n;
    p.emplace_back(a * std::cos(t), a * std::sin(t), b * t);
  }
  return p;
}

double polyline_length(const std::vector<Vec3>& p) {
  double L = 0;
  for (size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}

}  // namespace

// Isometry along the axis: the warped image of the straight axis segment z in [z0, z1] (r = 0)
// has arc length z1 − z0 exactly (compared with the straight length, to round-off); for r > 0
// the lines on the outer/inner side stretch/shorten by −r κ cos φ, which averages out over
// evenly spaced generator lines: their mean length equals the straight length (compared with
// the straight length within the O(h²) chord error of the sampling).
TEST(Centerline, WarpIsAnIsometryAlongTheAxis) {
  const Centerline c(angio::geometry::read_centerline_points(std::string(ANGIO_SOURCE_DIR) +
                                                             "/configs/centerlines/curved_arc_r15.txt"));
  const double z0 = 3.0, z1 = 21.0;  // the curved balloon's 18 mm
  // the warped axis sampled on a fine grid plus the centerline vertices (so that no chord cuts a
  // corner of the polyline) is the centerline piece itself
  std::vector<double> ss;
  for (int k = 0; k <= 720; ++k) ss.push_back(z0 + (z1 - z0) * k / 720);
  for (double s : c.arc_length())
    if (s > z0 && s < z1) ss.push_back(s);
  std::sort(ss.begin(), ss.end());
  std::vector<Vec3> axis_line;
  for (double s : ss) axis_line.push_back(c.map(0.3, s, 0.0));
  EXPECT_NEAR(polyline_length(axis_line), z1 - z0, 1e-12);
  double mean = 0;
  const int nth = 22;
  for (int i = 0; i < nth; ++i) {
    std::vector<Vec3> line;
    for (int k = 0; k <= 720; ++k) line.push_back(c.map(2 * pi * i / nth, z0 + (z1 - z0) * k / 720, 0.49));
    const double L = polyline_length(line);
    EXPECT_NEAR(L / (z1 - z0), 1.0, 0.49 / 15.0 + 1e-3);  // |r κ| bound per line
    mean += L / nth;
  }
  EXPECT_NEAR(mean, z1 - z0, 1e-4 * (z1 - z0));
}

// A warped point map(θ, s, r) is found again by closest(): arc length s and distance r, to
// round-off (compared with the (θ, s, r) it was made from), inside the centerline and on the
// straight extensions beyond its ends.
TEST(Centerline, ClosestInvertsTheWarp) {
  const Centerline c(helix(6.0, 2.0, 3.0, 60));
  for (double s : {-0.7, 0.0, 0.013, 1.0, 5.55, 9.9, c.length(), c.length() + 0.4})
    for (double th : {0.0, 1.0, 2.5, 4.0, 5.9})
      for (double r : {0.02, 0.49, 1.4}) {
        const auto p = c.closest(c.map(th, s, r));
        EXPECT_NEAR(p.s, s, 1e-11) << th << " " << r;
        EXPECT_NEAR(p.distance, r, 1e-12);
        EXPECT_NEAR(p.radial.dot(c.radial(th, s)), 1.0, 1e-12);
        EXPECT_NEAR(p.radial.dot(p.frame.tangent), 0.0, 1e-12);
      }
}

// Minimal twist on a planar curve: the rotation-minimizing frame does not rotate about the
// tangent, so the frame vector normal to the plane stays exactly the plane normal (compared
// with the analytic value e_y for an arc in the x–z plane), also between vertices (slerp).
TEST(Centerline, PlanarCurveFramesDoNotTwist) {
  const Centerline c(planar_arc(10.0, 12.0, 50));
  for (const auto& f : c.frames()) {
    EXPECT_NEAR(f.tangent.dot(f.normal1), 0, 1e-12);
    EXPECT_NEAR(f.normal1.norm(), 1, 1e-12);
    EXPECT_NEAR(f.normal1.y(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(f.normal2.y()), 1.0, 1e-12);
  }
  for (double s = 0; s <= c.length(); s += 0.173) {
    const auto f = c.frame(s);
    EXPECT_NEAR(std::abs(f.normal2.y()), 1.0, 1e-12);
    EXPECT_NEAR(f.tangent.cross(f.normal1).dot(f.normal2), 1.0, 1e-12);
  }
}

// Minimal twist on a space curve: relative to the Frenet frame (N, B) the RMF turns about the
// tangent at the rate −τ (Bishop 1975; angular velocity of the RMF is κB, of Frenet τT + κB).
// Compared with the analytic angle −τ s of a helix, to the O(h²) accuracy of the vertex
// tangents (h = 0.05 rad per segment).
TEST(Centerline, HelixFramesTurnAtMinusTorsion) {
  const double a = 2.0, b = 1.0, cc = std::sqrt(a * a + b * b), tau = b / (cc * cc);
  const int n = 400;
  const double tmax = 20.0;
  const Centerline c(helix(a, b, tmax, n));
  auto frenet_angle = [&](int i) {
    const double t = tmax * i / n;
    const Vec3 N(-std::cos(t), -std::sin(t), 0.0);  // principal normal of the helix
    const Vec3 T = Vec3(-a * std::sin(t), a * std::cos(t), b) / cc;
    const Vec3 B = T.cross(N);
    const Vec3 u = c.frames()[i].normal1;
    return std::atan2(u.dot(B), u.dot(N));
  };
  const double phi0 = frenet_angle(1);
  for (int i = 40; i < n; i += 40) {
    const double s = cc * tmax * (i - 1) / n;  // arc length from vertex 1
    double d = frenet_angle(i) - phi0 + tau * s;
    d = std::remainder(d, 2 * pi);
    EXPECT_NEAR(d, 0.0, 2e-3) << "vertex " << i;
  }
}

// A straight centerline along +z reproduces the cylindrical coordinates exactly (compared with
// (r cos θ, r sin θ, s) + start point): frames constant e_x, e_y.
TEST(Centerline, StraightCenterlineIsCylindricalCoordinates) {
  const Centerline c({Vec3(0.5, -1, 2), Vec3(0.5, -1, 4), Vec3(0.5, -1, 9)});
  EXPECT_DOUBLE_EQ(c.length(), 7.0);
  for (double s : {0.0, 1.3, 2.0, 6.9})
    for (double th : {0.0, 0.7, 3.0}) {
      const Vec3 x = c.map(th, s, 0.45);
      EXPECT_LT((x - Vec3(0.5 + 0.45 * std::cos(th), -1 + 0.45 * std::sin(th), 2 + s)).norm(), 1e-14);
    }
}

TEST(Centerline, InvalidInputs) {
  EXPECT_THROW(Centerline({Vec3(0, 0, 0)}), std::invalid_argument);
  EXPECT_THROW(Centerline({Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 0, 1)}), std::invalid_argument);
  EXPECT_THROW(angio::geometry::read_centerline("/nonexistent/centerline.txt"), std::runtime_error);
}

// Scene key shape {file} | {points} | [[x, y, z], ...]; errors name the scene file and key path.
TEST(Centerline, FromSceneNamesFileAndKey) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "angio_centerline_scene_test";
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "cl.txt");
    f << "# x y z\n0 0 0\n0 0 1\n0, 0, 2\n";
    std::ofstream s(dir / "scene.yaml");
    s << "a: {centerline: {file: cl.txt}}\nb: {centerline: [[0, 0, 0], [1, 0, 0]]}\n"
         "c: {centerline: {file: missing.txt}}\nd: {centerline: {points: [[0, 0, 0], [0, 0, 0]]}}\n";
  }
  const auto root = angio::scene::load_scene((dir / "scene.yaml").string());
  EXPECT_DOUBLE_EQ(angio::geometry::centerline_from_scene(root.child("a").child("centerline")).length(), 2.0);
  EXPECT_DOUBLE_EQ(angio::geometry::centerline_from_scene(root.child("b").child("centerline")).length(), 1.0);
  for (const char* key : {"c", "d"}) {
    try {
      angio::geometry::centerline_from_scene(root.child(key).child("centerline"));
      ADD_FAILURE() << "expected SceneError for " << key;
    } catch (const angio::scene::SceneError& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find("scene.yaml"), std::string::npos) << w;
      EXPECT_NE(w.find(std::string(key) + ".centerline"), std::string::npos) << w;
    }
  }
  fs::remove_all(dir);
}
