// Interface quasi-Newton with an inverse Jacobian from a least-squares model (IQN-ILS;
// Degroote, Bathe & Vierendeels 2009, Comput. Struct. 87, Eqs. 10–14; as in preCICE).
// With H the fixed-point map q -> q~ and r = q~ − q, the differences of the iterates
//   V = [r_k − r_{k−1}, …],  W = [q~_k − q~_{k−1}, …]
// (of this step, then of up to `reused_steps` earlier accepted steps) give the update
//   α = argmin ||V α + r_k||,   q_{k+1} = q~_k + W α.
// Without any column (the very first iteration of a run) it relaxes: q_1 = q_0 + ω_0 r_0.
// Unlike Aitken's single factor, the least-squares model resolves the individual unstable
// interface modes (here: short-wave strut indentations of the balloon) and relaxes only them.
// Columns that are nearly linearly dependent are dropped while the QR factorization is built
// (filter: a column is kept if the part orthogonal to the kept ones exceeds `filter` times its
// norm; the "QR2" filter of Haelterman et al. 2016). A model whose step is shorter than
// `stagnation` times the residual is discarded (all columns) and the update relaxes with ω_0:
// otherwise the same iterate comes back unchanged forever (seen at the first contact of the
// curved free expansion, where a column from before the contact made r + W α = 0).
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "angio/coupler/acceleration.hpp"
#include "angio/scene/keys_generated.hpp"

namespace angio::coupler {

struct IqnIlsOptions {
  double initial_relaxation = scene::keys::defaults::coupling_initial_relaxation;  // ω_0 of the first update
  int reused_steps = scene::keys::defaults::coupling_iqn_reused_steps;             // accepted steps whose columns stay
  int max_columns = scene::keys::defaults::coupling_iqn_max_columns;               // all columns together (newest kept)
  double filter = scene::keys::defaults::coupling_iqn_filter;                      // QR2 filter threshold
  // restart when ||q_{k+1} − q_k|| < stagnation ||r_k||
  double stagnation = scene::keys::defaults::coupling_iqn_stagnation;
};

// std::invalid_argument naming `method` unless 0 < initial_relaxation, reused_steps >= 0,
// max_columns >= 1, 0 < filter < 1 and 0 <= stagnation < 1.
void check_iqn_options(const IqnIlsOptions& o, const std::string& method);

class IqnIls : public Acceleration {
 public:
  explicit IqnIls(IqnIlsOptions o);
  void begin_step() override;
  void restart() override;  // also drops the columns of earlier steps
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) override;
  void end_step(bool accepted) override;
  double last_factor() const override { return factor_; }
  std::string name() const override { return "iqn-ils"; }
  // Columns used in the last update (after filtering), for logs and tests.
  int last_columns() const { return last_columns_; }
  // Restarts of the model after a vanishing step, since construction.
  int restarts() const { return restarts_; }

 private:
  struct Columns {
    std::vector<Eigen::VectorXd> v, w;  // newest first
  };
  IqnIlsOptions o_;
  Columns current_;               // of the step in progress
  std::deque<Columns> previous_;  // of earlier accepted steps, newest first
  Eigen::VectorXd r_prev_, qt_prev_;
  double factor_;
  int last_columns_ = 0;
  int restarts_ = 0;
};

}  // namespace angio::coupler
