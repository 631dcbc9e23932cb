// Interface Newton–Krylov (docs/design.md §5.5): the Newton step of the interface residual
// r(q) = H(q) − q, (I − J) δ = r with J = ∂H/∂q, solved by GMRES (Saad & Schultz 1986) on products
// J v that the participants compute from their linearizations at their last solves (the beam's
// tangent with the planes' penalty, the solid's tangent as last factorized: an inexact Newton,
// Dembo, Eisenstat & Steihaug 1982). Unlike a quasi-Newton model, which learns one direction per
// coupling iteration, each product costs a back-substitution in each participant instead of a
// nonlinear solve, so one coupling iteration can see the interface's response in many directions
// (a strut's load spreads through the balloon's membrane to its neighbours, which the diagonal
// planes of the robin scheme do not know).
#pragma once

#include <functional>

#include "angio/coupler/acceleration.hpp"
#include "angio/scene/keys_generated.hpp"

namespace angio::coupler {

struct NewtonKrylovOptions {
  // the scene's coupling.newton_krylov keys (core/scene/keys.yaml): meaning and defaults there
  int max_products = scene::keys::defaults::coupling_newton_krylov_max_products;  // J v per coupling iteration
  double tolerance = scene::keys::defaults::coupling_newton_krylov_tolerance;  // |r − (I − J)δ| <= tolerance |r|
};

class NewtonKrylov : public Acceleration {
 public:
  explicit NewtonKrylov(NewtonKrylovOptions o) : o_(o) {}
  bool uses_jacobian() const override { return true; }
  void begin_step() override {}
  // q + δ. When a product fails (a participant cannot linearize, e.g. before its first
  // factorization) the plain fixed-point update q + r.
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) override;
  void end_step(bool) override {}
  double last_factor() const override { return 1.0; }
  std::string name() const override { return "newton-krylov"; }
  int last_products() const { return last_products_; }

 private:
  NewtonKrylovOptions o_;
  int last_products_ = 0;
};

}  // namespace angio::coupler
