// Interface quasi-Newton with an inverse Jacobian carried across steps (IQN-IMVJ, the
// multi-vector Jacobian of Bogaers, Kok, Reddy & Franz, Comput Methods Appl Mech Eng 279 (2014)
// 113; as IQN-IMVJ in preCICE, Lindner, Mehl & Uekermann 2017). With H the fixed-point map
// q -> q~, r = q~ − q and the differences of this step's iterates V = [r_k − r_{k−1}, …],
// W = [q~_k − q~_{k−1}, …], the inverse Jacobian J (of Δr -> Δq~) is the one of the steps before,
// corrected on the span of V only:
//   J = J_prev + (W − J_prev V)(VᵀV)⁻¹Vᵀ,   q_{k+1} = q~_k − J r_k,
// and J becomes J_prev of the next step when the step is accepted. With J_prev = 0 this is
// IQN-ILS without reuse; unlike IQN-ILS with reused columns, an old step's information is not a
// column the least-squares model must fit next to the new ones but the background the new
// columns correct, so contradicting columns of a changed contact set cannot make the model
// singular. Even the first update of a step is a quasi-Newton step with J_prev.
// J_prev is kept as a sum of the low-rank corrections of the accepted steps (J_prev x =
// Σ A_i (B_iᵀ x), B_i = Q of V's filtered QR, A_i = (W − J_prev V) R⁻¹), never as an n x n
// matrix, and restarts after `reused_steps` steps (preCICE's restart mode RS-ZERO) from the
// last step's own model (its correction from 0, W R⁻¹ with B = Q: IQN-ILS's inverse Jacobian).
// The QR2 filter and the stagnation guard are IQN-ILS's (iqn_ils.hpp); a stagnating model drops
// J_prev as well.
#pragma once

#include <vector>

#include "angio/coupler/acceleration.hpp"
#include "angio/coupler/iqn_ils.hpp"

namespace angio::coupler {

class IqnImvj : public Acceleration {
 public:
  // o.reused_steps: accepted steps whose corrections make up J_prev before it restarts from 0
  // (0: none carried, IQN-ILS without reuse); o.max_columns: the newest columns of a step used.
  explicit IqnImvj(IqnIlsOptions o);
  void begin_step() override;
  void restart() override;  // also drops J_prev
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) override;
  void end_step(bool accepted) override;
  double last_factor() const override { return factor_; }
  std::string name() const override { return "iqn-imvj"; }
  int last_columns() const { return last_columns_; }       // this step's columns in the last update
  int carried_steps() const { return int(prev_.size()); }  // accepted steps in J_prev
  int restarts() const { return restarts_; }               // stagnation restarts since construction
  // J_prev x, the Jacobian carried from the steps before (for tests and diagnostics)
  Eigen::VectorXd carried_jacobian_times(const Eigen::VectorXd& x) const { return apply_prev_(x); }

 private:
  struct Correction {
    Eigen::MatrixXd a, b;  // J_prev += a bᵀ
  };
  Eigen::VectorXd apply_prev_(const Eigen::VectorXd& x) const;  // J_prev x
  IqnIlsOptions o_;
  std::vector<Correction> prev_;  // J_prev, oldest first
  // this step's columns, newest first: V, W and W − J_prev V (computed once, as a column arrives)
  std::vector<Eigen::VectorXd> v_, w_, d_;
  Eigen::VectorXd r_prev_, qt_prev_;
  Correction last_;  // the correction of the last update: J_prev's next term when the step is accepted
  // the last update's filtered QR of V: the kept columns and R (kept x kept)
  std::vector<int> last_kept_;
  Eigen::MatrixXd last_r_;
  // the kept columns of `columns` (this step's, as v_) times R⁻¹
  Eigen::MatrixXd times_r_inverse_(const std::vector<Eigen::VectorXd>& columns) const;
  double factor_;
  int last_columns_ = 0;
  int restarts_ = 0;
};

}  // namespace angio::coupler
