// Acceleration of the Dirichlet–Neumann fixed-point iteration q_{k+1} = q_k + Δq_k
// (docs/design.md §5.4). The coupling loop only sees this interface, so IQN-ILS or other schemes
// can be added next to Aitken without touching the loop.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace angio::coupler {

class Acceleration {
 public:
  virtual ~Acceleration() = default;
  // Called at the start of every load step (also after a rejected attempt).
  virtual void begin_step() = 0;
  // Drops everything the acceleration has learned, also from earlier steps, so that the next
  // update (k = 0) starts afresh from the current iterate (coupling.restart_growth).
  virtual void restart() { begin_step(); }
  // Given the current input q_k and the residual r_k = q~_k − q_k of iteration k (0-based within
  // the step), returns the next input q_{k+1}.
  virtual Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) = 0;
  // Components of the next update's q and r that were set anew since the last update instead of
  // following the map (robin: a contact plane that appeared starts where the solid put it, one that
  // vanished is no longer iterated). The secant difference the next update forms leaves them out
  // (zero rows): a jump of up to the search radius would otherwise enter the model as the map's
  // response (IQN: the least-squares step moved planes without force by as much; Aitken: its
  // factor). Constant relaxation, without differences, ignores it.
  void mark_discontinuous(std::vector<Eigen::Index> components) { discontinuous_ = std::move(components); }
  // Accelerations that take the map's Jacobian (newton-krylov) get J v, the derivative of the map
  // q -> q~ along v at the last iterate, from the interface scheme and the participants. J v returns an
  // empty vector when it cannot be had.
  using JacobianProduct = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
  virtual bool uses_jacobian() const { return false; }
  void set_jacobian(JacobianProduct jv) { jacobian_ = std::move(jv); }
  // Called when a step converged (e.g. to carry the last relaxation factor to the next step).
  virtual void end_step(bool accepted) = 0;
  // Relaxation factor used in the last update (for logging; 1 for schemes without one).
  virtual double last_factor() const = 0;
  virtual std::string name() const = 0;

 protected:
  // The components marked since the last update, handed over once: every update() takes them first
  // (a mark applies to the one difference that update forms, none later).
  std::vector<Eigen::Index> take_discontinuous() { return std::exchange(discontinuous_, {}); }
  JacobianProduct jacobian_;
  // Zeroes those rows of a difference.
  static void drop_rows(Eigen::VectorXd& difference, const std::vector<Eigen::Index>& rows) {
    for (Eigen::Index i : rows)
      if (i >= 0 && i < difference.size()) difference[i] = 0.0;
  }

 private:
  std::vector<Eigen::Index> discontinuous_;
};

}  // namespace angio::coupler
