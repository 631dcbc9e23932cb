// Reference-configuration validity of a mesh: the Jacobian determinant of the isoparametric map
// must be positive wherever the element is integrated and at its nodes. A curved tet10 can be
// positive at every Gauss point and still fold at a corner, so both are checked.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "angio/solid/mesh.hpp"

namespace angio::solid {

std::string first_invalid_element(const Mesh& m) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN, X;
  // the reference nodes per element type, once (indexed by ElemType: Hex8, Tet4, Tet10)
  const std::vector<Vec3d> nodes_of[] = {reference_nodes(ElemType::Hex8), reference_nodes(ElemType::Tet4),
                                         reference_nodes(ElemType::Tet10)};
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const auto& el = m.elements[e];
    X.resize(el.nn(), 3);
    for (int a = 0; a < el.nn(); ++a) X.row(a) = m.X[el.n[a]].transpose();
    auto det_at = [&](const double* xi) {
      shape(el.type, xi, N, dN);
      return (X.transpose() * dN).determinant();
    };
    double detJ = 0.0;
    std::string where;
    for (const auto& qp : volume_rule(el.type))
      if (!((detJ = det_at(qp.xi)) > 0.0)) {  // zero, negative or NaN
        where = "a Gauss point";
        break;
      }
    if (where.empty()) {
      const auto& nodes = nodes_of[int(el.type)];
      for (size_t a = 0; a < nodes.size(); ++a)
        if (!((detJ = det_at(nodes[a].data())) > 0.0)) {
          where = "its local node " + std::to_string(a);
          break;
        }
    }
    if (where.empty()) continue;
    const Vec3d c = element_centroid(m, int(e));
    std::ostringstream s;
    s.precision(4);
    s << "element " << e << " (counted from 0 in file order; " << name(el.type) << ", block '"
      << m.blocks[el.block].name << "', centroid (" << c.x() << ", " << c.y() << ", " << c.z()
      << ")) has the Jacobian determinant " << detJ << " at " << where << " (inverted or degenerate)";
    return s.str();
  }
  return {};
}

}  // namespace angio::solid

namespace angio::solid {

std::vector<std::string> part_names(const Mesh& mesh) {
  std::vector<std::string> names;
  for (const auto& b : mesh.blocks)
    if (std::find(names.begin(), names.end(), b.part) == names.end()) names.push_back(b.part);
  return names;
}

std::string block_names(const Mesh& m) {
  std::string s;
  for (const auto& b : m.blocks) s += (s.empty() ? "" : ", ") + b.name;
  return s.empty() ? "none" : s;
}

std::string surface_names(const Mesh& m, const std::string& prefix) {
  std::string s;
  for (const auto& f : m.surfaces) {
    const bool prefixed = f.name.compare(0, prefix.size(), prefix) == 0;
    s += (s.empty() ? "" : ", ") + (prefixed ? f.name.substr(prefix.size()) : f.name);
  }
  return s.empty() ? "none" : s;
}

}  // namespace angio::solid
