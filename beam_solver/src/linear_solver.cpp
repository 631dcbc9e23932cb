#include "angio/beam/linear_solver.hpp"

#include <Eigen/KLUSupport>
#include <Eigen/SparseLU>
#include <Eigen/UmfPackSupport>
#include <stdexcept>

namespace angio::beam {

namespace {

template <class Impl>
class EigenBackend : public LinearSolver {
 public:
  explicit EigenBackend(const char* n) : name_(n) {}
  const char* name() const override { return name_; }
  void factorize(const SpMat& K) override {
    if (K.rows() != rows_ || K.nonZeros() != nnz_) {
      solver_.analyzePattern(K);
      rows_ = K.rows();
      nnz_ = K.nonZeros();
    }
    solver_.factorize(K);
    if (solver_.info() != Eigen::Success)
      throw std::runtime_error(std::string(name_) +
                               ": factorization failed (singular stiffness matrix? "
                               "check supports: rigid-body modes must be removed)");
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) override {
    Eigen::VectorXd x = solver_.solve(b);
    if (solver_.info() != Eigen::Success) throw std::runtime_error(std::string(name_) + ": solve failed");
    return x;
  }

 private:
  const char* name_;
  Impl solver_;
  Eigen::Index rows_ = -1, nnz_ = -1;
};

}  // namespace

std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name) {
  if (name == "umfpack") return std::make_unique<EigenBackend<Eigen::UmfPackLU<SpMat>>>("umfpack");
  if (name == "klu") return std::make_unique<EigenBackend<Eigen::KLU<SpMat>>>("klu");
  if (name == "sparselu")
    return std::make_unique<EigenBackend<Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>>>>("sparselu");
  throw std::invalid_argument("unknown linear solver '" + name + "' (umfpack, klu, sparselu)");
}

}  // namespace angio::beam
