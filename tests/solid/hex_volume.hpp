// Signed volume of a hex8 of a mesh from its 8 nodes (sum of the 6 tetrahedra of the diagonal split
// 0–6): exact for any hex8 with planar faces, positive for a valid one. For the generator tests.
#pragma once
#include "angio/solid/mesh.hpp"

namespace angio::solid::test {

inline double hex_volume(const Mesh& m, const Element& e) {
  static const int tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  double v = 0.0;
  for (const auto& t : tets) {
    const Vec3d a = m.X[e.n[t[1]]] - m.X[e.n[t[0]]], b = m.X[e.n[t[2]]] - m.X[e.n[t[0]]],
                c = m.X[e.n[t[3]]] - m.X[e.n[t[0]]];
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

}  // namespace angio::solid::test
