// Sparse linear solve behind one interface; backend chosen by name in the scene
// (stent.solver.linear_solver): "klu" (SuiteSparse, default), "umfpack" (SuiteSparse),
// "sparselu" (Eigen).
#pragma once

#include <Eigen/Sparse>
#include <memory>
#include <string>

namespace angio::beam {

using SpMat = Eigen::SparseMatrix<double>;

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  virtual const char* name() const = 0;
  // Solves K x = b. The sparsity pattern is analysed once and reused while it stays the same.
  // Throws std::runtime_error when the factorization fails (singular matrix).
  Eigen::VectorXd solve(const SpMat& K, const Eigen::VectorXd& b) {
    factorize(K);
    return solve(b);
  }
  // The same in two parts: K factorized once, then any number of right-hand sides. K must live as
  // long as the solves (UMFPACK's solve reads the matrix again).
  virtual void factorize(const SpMat& K) = 0;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b) = 0;
};

std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name);

}  // namespace angio::beam
