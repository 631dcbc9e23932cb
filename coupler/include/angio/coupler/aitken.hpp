// Aitken's dynamic relaxation (Irons & Tuck 1969; Küttler & Wall 2008, Eq. 44):
//   ω_k = −ω_{k−1} · r_{k−1}·(r_k − r_{k−1}) / ||r_k − r_{k−1}||²,   q_{k+1} = q_k + ω_k r_k.
// First iteration of a step: ω_0 = sign(ω_prev)·min(ω_init, |ω_prev|) with ω_prev the last factor
// of the previous step (ω_init at the very first step), as in docs/design.md §5.4. |ω| is capped at ω_max.
#pragma once

#include "angio/coupler/acceleration.hpp"

namespace angio::coupler {

class Aitken : public Acceleration {
 public:
  Aitken(double initial, double maximum);
  void begin_step() override;
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) override;
  void end_step(bool accepted) override;
  double last_factor() const override { return omega_; }
  std::string name() const override { return "aitken"; }

 private:
  double initial_, maximum_;
  double omega_;             // factor of the current iteration
  double omega_prev_;        // last factor of the previous accepted step
  double omega_step_start_;  // ω_prev when the current step began (restored on rejection)
  Eigen::VectorXd r_prev_;
};

// Constant under-relaxation q_{k+1} = q_k + ω r_k (the baseline that Aitken improves on).
class ConstantRelaxation : public Acceleration {
 public:
  explicit ConstantRelaxation(double omega) : omega_(omega) {}
  void begin_step() override {}
  Eigen::VectorXd update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int) override { return q + omega_ * r; }
  void end_step(bool) override {}
  double last_factor() const override { return omega_; }
  std::string name() const override { return "constant"; }

 private:
  double omega_;
};

}  // namespace angio::coupler
