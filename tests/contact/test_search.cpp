// Spatial search (AABB tree) against brute force.
#include <gtest/gtest.h>

#include "helpers.hpp"

using namespace angio::contact;
using namespace angio::contact::test;

// Compares against: brute force over all faces — (1) the candidate set equals the set of faces whose inflated box
// contains the point, (2) the closest face/point equals the closest over all faces, for random points around a
// deformed quad4 tube and a tri6 tube, after a rebuild and after a refit.
TEST(Search, MatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  for (FaceKind k : {FaceKind::Quad4, FaceKind::Tri6}) {
    Mesh m = cylinder(k, 0.5, 3.0, 24, 20);
    SurfaceSearch S(m.surface, 0.15);
    for (int pass = 0; pass < 2; ++pass) {
      // deform (bulge + noise), then rebuild (pass 0) or refit (pass 1)
      for (Vec3& p : m.x) {
        const double b = 1.0 + 0.1 * std::sin(p.z()) * (pass + 1);
        p.x() *= b;
        p.y() *= b;
        p += 0.01 * Vec3(U(rng), U(rng), U(rng));
      }
      S.update(m.x, pass == 0);
      int found = 0;
      std::vector<int> cand;
      for (int i = 0; i < 400; ++i) {
        const Vec3 x = cyl(0.55 + 0.25 * U(rng), M_PI * U(rng), 1.5 + 1.6 * U(rng));
        S.candidates(x, cand);
        std::vector<int> ref;
        for (int f = 0; f < static_cast<int>(m.surface.faces.size()); ++f)
          if (S.face_box(f).contains(x)) ref.push_back(f);
        EXPECT_EQ(cand, ref);
        const SurfaceProjection a = S.closest(x), b = S.closest_brute_force(x);
        EXPECT_EQ(a.found, b.found);
        EXPECT_EQ(a.face, b.face);
        if (a.found) {
          ++found;
          EXPECT_EQ(a.proj.distance, b.proj.distance);
          EXPECT_LE(a.proj.distance, 0.15);
        }
      }
      EXPECT_GT(found, 100);
    }
  }
}

// Compares against: the definition of free edges (edges used by one face only) on an open tube: only the two end
// rings are free; and the rejection of points behind the rim.
TEST(Search, FreeEdgesAndRim) {
  Mesh m = flat_quads(2, 2, 1.0, 1.0);
  SurfaceSearch S(m.surface, 1.0);
  S.update(m.x);
  int free_edges = 0;
  for (int f = 0; f < 4; ++f)
    for (int e = 0; e < 4; ++e) free_edges += (S.free_mask(f) >> e) & 1u;
  EXPECT_EQ(free_edges, 8);
  // behind the plate (z < 0) and beyond its rim: rejected; in front beyond the rim: point-to-edge distance
  EXPECT_FALSE(S.closest(Vec3(2.3, 1.0, -0.1)).found);
  const SurfaceProjection p = S.closest(Vec3(2.3, 0.6, 0.4));
  ASSERT_TRUE(p.found);
  EXPECT_EQ(p.proj.location, Location::Edge);
  EXPECT_NEAR(p.proj.d, 0.5, 1e-14);
  // behind the plate inside the rim: a genuine penetration
  const SurfaceProjection q = S.closest(Vec3(1.7, 1.0, -0.1));
  ASSERT_TRUE(q.found);
  EXPECT_NEAR(q.proj.d, -0.1, 1e-14);
}

// Compares against: brute force — the query with the boxes shrunk by s returns exactly the faces whose
// (inflated) box shrunk by s on every side contains the point, after a rebuild and after a refit.
TEST(Search, ShrunkQueryMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  Mesh m = cylinder(FaceKind::Quad4, 0.5, 3.0, 24, 20);
  SurfaceSearch S(m.surface, 0.3);
  S.update(m.x);
  std::vector<Aabb> boxes(m.surface.faces.size());
  for (std::size_t f = 0; f < boxes.size(); ++f) boxes[f] = S.face_box(int(f));
  AabbTree tree;
  tree.build(boxes);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {  // move the boxes (a refit keeps the topology of the first build)
      for (Aabb& b : boxes) {
        const Vec3 t = 0.05 * Vec3(U(rng), U(rng), U(rng));
        b.lo += t;
        b.hi += t;
      }
      tree.refit(boxes);
    }
    int nonempty = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 x = cyl(0.5 + 0.3 * U(rng), M_PI * U(rng), 1.5 + 1.6 * U(rng));
      for (double s : {0.0, 0.1, 0.25, 0.29}) {
        std::vector<int> got;
        tree.query(x, s, got);
        std::sort(got.begin(), got.end());
        std::vector<int> ref;
        for (int f = 0; f < int(boxes.size()); ++f) {
          Aabb b = boxes[f];
          b.inflate(-s);
          if (b.contains(x)) ref.push_back(f);
        }
        EXPECT_EQ(got, ref) << "pass " << pass << " point " << i << " shrink " << s;
        nonempty += !ref.empty() && s > 0.2;
      }
    }
    EXPECT_GT(nonempty, 20);  // the shrunk queries are not all empty
  }
}
