#include "angio/coupler/newton_krylov.hpp"

#include <unsupported/Eigen/IterativeSolvers>

#include "angio/common/log.hpp"

namespace angio::coupler {
namespace {

// I − J as a matrix-free operator for Eigen's GMRES (the "matrix-free solvers" pattern of Eigen's
// documentation): a product calls the participants; a failed one ends the solve by exception.
class InterfaceOperator;
struct ProductFailed {};

}  // namespace
}  // namespace angio::coupler

namespace Eigen::internal {
template <>
struct traits<angio::coupler::InterfaceOperator> : public traits<Eigen::SparseMatrix<double>> {};
}  // namespace Eigen::internal

namespace angio::coupler {
namespace {

class InterfaceOperator : public Eigen::EigenBase<InterfaceOperator> {
 public:
  using Scalar = double;
  using RealScalar = double;
  using StorageIndex = int;
  enum { ColsAtCompileTime = Eigen::Dynamic, MaxColsAtCompileTime = Eigen::Dynamic, IsRowMajor = false };

  InterfaceOperator(const Acceleration::JacobianProduct& jv, const std::vector<Eigen::Index>& dropped, Eigen::Index n)
      : jv_(jv), dropped_(dropped), n_(n) {}
  Eigen::Index rows() const { return n_; }
  Eigen::Index cols() const { return n_; }
  template <typename Rhs>
  Eigen::Product<InterfaceOperator, Rhs, Eigen::AliasFreeProduct> operator*(const Eigen::MatrixBase<Rhs>& x) const {
    return Eigen::Product<InterfaceOperator, Rhs, Eigen::AliasFreeProduct>(*this, x.derived());
  }
  // (I − J) v; the rows set anew since the last update (Acceleration::mark_discontinuous) are not
  // the map's response to anything: there J is taken as 0.
  Eigen::VectorXd apply(const Eigen::VectorXd& v) const {
    if (v.squaredNorm() == 0.0) return Eigen::VectorXd::Zero(n_);
    Eigen::VectorXd w = v;
    for (Eigen::Index i : dropped_) w[i] = 0.0;
    Eigen::VectorXd jw = jv_(w);
    ++products;
    if (jw.size() != n_ || !jw.allFinite()) throw ProductFailed{};
    for (Eigen::Index i : dropped_) jw[i] = 0.0;
    return v - jw;
  }
  mutable int products = 0;

 private:
  const Acceleration::JacobianProduct& jv_;
  const std::vector<Eigen::Index>& dropped_;
  Eigen::Index n_;
};

}  // namespace
}  // namespace angio::coupler

namespace Eigen::internal {
template <typename Rhs>
struct generic_product_impl<angio::coupler::InterfaceOperator, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<angio::coupler::InterfaceOperator, Rhs,
                                generic_product_impl<angio::coupler::InterfaceOperator, Rhs>> {
  template <typename Dest>
  static void scaleAndAddTo(Dest& dst, const angio::coupler::InterfaceOperator& lhs, const Rhs& rhs, double alpha) {
    dst.noalias() += alpha * lhs.apply(rhs);
  }
};
}  // namespace Eigen::internal

namespace angio::coupler {

Eigen::VectorXd NewtonKrylov::update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int) {
  const std::vector<Eigen::Index> dropped = take_discontinuous();
  last_products_ = 0;
  if (!jacobian_ || r.squaredNorm() == 0.0) return q + r;
  const InterfaceOperator A(jacobian_, dropped, r.size());
  Eigen::GMRES<InterfaceOperator, Eigen::IdentityPreconditioner> gmres;
  gmres.setMaxIterations(o_.max_products);
  gmres.set_restart(o_.max_products);  // no restart within the budget
  gmres.setTolerance(o_.tolerance);
  gmres.compute(A);
  Eigen::VectorXd delta;
  try {
    delta = gmres.solve(r);
  } catch (const ProductFailed&) {
    last_products_ = A.products;
    return q + r;
  }
  last_products_ = A.products;
  LOG_DEBUG("newton-krylov: " << last_products_ << " products, linear residual " << gmres.error()
                              << ", |delta| / |r| = " << delta.norm() / r.norm());
  if (!delta.allFinite()) return q + r;
  return q + delta;
}

}  // namespace angio::coupler
