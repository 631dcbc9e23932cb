// Distorted cube meshes for patch tests (hex8; tet4 = Kuhn split of each hex into 6 tets; tet10 =
// tet4 with mid-edge nodes; interior vertices are perturbed). Node set "boundary": nodes on the cube faces.
#include <algorithm>
#include <map>
#include <random>

#include "angio/solid/mesh.hpp"

namespace angio_test {
using namespace angio::solid;

Mesh cube_mesh(ElemType t, int n, double perturb, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-perturb, perturb);
  Mesh m;
  m.blocks.push_back({"cube", "test"});
  auto id = [&](int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; };
  std::vector<int> boundary;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        Vec3d x(double(i) / n, double(j) / n, double(k) / n);
        const bool b = i == 0 || j == 0 || k == 0 || i == n || j == n || k == n;
        if (!b)
          x += Vec3d(U(rng), U(rng), U(rng)) / n;
        else
          boundary.push_back(id(i, j, k));
        m.X.push_back(x);
      }
  std::map<std::pair<int, int>, int> mid;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int v[8] = {id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
                          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
        if (t == ElemType::Hex8) {
          Element e;
          e.type = ElemType::Hex8;
          for (int a = 0; a < 8; ++a) e.n[a] = v[a];
          m.elements.push_back(e);
          continue;
        }
        // Kuhn: 6 tets around the diagonal v0-v6
        static const int tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                       {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
        for (const auto& tt : tets) {
          Element e;
          e.type = t;
          for (int a = 0; a < 4; ++a) e.n[a] = v[tt[a]];
          const Vec3d d1 = m.X[e.n[1]] - m.X[e.n[0]], d2 = m.X[e.n[2]] - m.X[e.n[0]], d3 = m.X[e.n[3]] - m.X[e.n[0]];
          if (d1.cross(d2).dot(d3) < 0) std::swap(e.n[1], e.n[2]);
          if (t == ElemType::Tet10) {
            static const int ed[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
            for (int q = 0; q < 6; ++q) {
              const int p0 = e.n[ed[q][0]], p1 = e.n[ed[q][1]];
              const auto key = std::minmax(p0, p1);
              auto it = mid.find(key);
              if (it == mid.end()) {
                Vec3d x = 0.5 * (m.X[p0] + m.X[p1]);
                const bool b0 = std::find(boundary.begin(), boundary.end(), p0) != boundary.end();
                const bool b1 = std::find(boundary.begin(), boundary.end(), p1) != boundary.end();
                const int nid = int(m.X.size());
                bool on_face = false;
                if (b0 && b1) {
                  // on a cube face iff both ends share a boundary coordinate
                  for (int c = 0; c < 3; ++c)
                    for (double val : {0.0, 1.0})
                      if (std::abs(m.X[p0](c) - val) < 1e-12 && std::abs(m.X[p1](c) - val) < 1e-12) on_face = true;
                }
                if (on_face) boundary.push_back(nid);
                // Mid-edge nodes stay at the edge midpoints (straight-sided tet10): with curved edges
                // the 4-point rule no longer integrates grad N det J exactly and the patch test
                // holds only up to the quadrature error (~1e-4 relative).
                m.X.push_back(x);
                it = mid.emplace(key, nid).first;
              }
              e.n[4 + q] = it->second;
            }
          }
          m.elements.push_back(e);
        }
      }
  m.node_sets["boundary"] = boundary;
  return m;
}
}  // namespace angio_test
