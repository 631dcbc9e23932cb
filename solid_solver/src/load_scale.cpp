#include "angio/solid/load_scale.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "angio/solid/elements.hpp"

namespace angio::solid {

double pressure_load_norm(const Mesh& mesh, const std::vector<std::pair<std::string, double>>& pressures) {
  std::vector<Vec3d> f(mesh.X.size(), Vec3d::Zero());
  Eigen::MatrixXd X;
  Eigen::VectorXd fe;
  for (const auto& [name, p] : pressures) {
    const SurfaceSet* s = mesh.surface(name);
    if (!s) throw std::invalid_argument("pressure_load_norm: no surface set '" + name + "' in the mesh");
    if (p == 0.0) continue;
    for (const auto& face : s->faces) {
      X.resize(face.nn(), 3);
      for (int a = 0; a < face.nn(); ++a) X.row(a) = mesh.X[face.n[a]].transpose();
      face_pressure(face.type, X, p, fe, nullptr);
      for (int a = 0; a < face.nn(); ++a) f[face.n[a]] += fe.segment<3>(3 * a);
    }
  }
  double sq = 0.0;
  for (const auto& v : f) sq += v.squaredNorm();
  return std::sqrt(sq);
}

}  // namespace angio::solid
