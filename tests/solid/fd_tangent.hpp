// Central finite differences of an element force with respect to its nodal displacements, for the
// tangent checks of the element kernels.
#pragma once
#include <Eigen/Dense>

namespace angio_test {

// force(u, f) evaluates the force vector (3n) at the nodal displacements u (n x 3).
template <class Force>
Eigen::MatrixXd fd_tangent(const Eigen::MatrixXd& u, Force force, double h = 1e-6) {
  Eigen::VectorXd fp, fm;
  Eigen::MatrixXd K;
  for (int j = 0; j < u.size(); ++j) {
    Eigen::MatrixXd up = u, um = u;
    up(j / 3, j % 3) += h;
    um(j / 3, j % 3) -= h;
    force(up, fp);
    force(um, fm);
    if (j == 0) K.resize(fp.size(), u.size());
    K.col(j) = (fp - fm) / (2 * h);
  }
  return K;
}

}  // namespace angio_test
