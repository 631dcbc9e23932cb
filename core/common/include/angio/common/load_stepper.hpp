// Pseudo-time load stepping with step cutting, shared by the coupler and the standalone solvers.
//
// A step that fails (no Newton or coupling convergence) is retried with half the increment; after
// a success the increment grows back (doubling) toward the nominal one, never stepping across a
// point of the nominal grid or a load-curve corner (TimeSettings::stops), so corners are hit
// exactly. With adaptive steps (TimeSettings::max_step) an easy step (at most easy_iterations
// iterations) at full size lets the increment double further, up to max_step, landing on the
// nominal grid; a harder one brings it back to the nominal step. Below the minimum increment the
// stepper gives up with an error naming the time and the increment.
#pragma once

#include <stdexcept>
#include <string>

#include "angio/scene/load_curve.hpp"

namespace angio {

class StepFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LoadStepper {
 public:
  explicit LoadStepper(const scene::TimeSettings& settings);

  bool finished() const;
  int step() const { return step_; }           // 1-based index of the step being attempted
  double time() const { return t_ + dt_; }     // end time of the step being attempted
  double previous_time() const { return t_; }  // last committed time
  double increment() const { return dt_; }
  int cuts() const { return cuts_; }  // cuts of the current step so far

  // iterations: what the accepted step needed (coupling or Newton iterations; adaptive steps).
  void accept(int iterations);
  // Halves the increment; throws StepFailure (with `reason`) when it would fall below min_step.
  void reject(const std::string& reason);

 private:
  void clamp_to_grid();
  scene::TimeSettings s_;
  double nominal_;
  double t_;
  double dt_;
  int step_ = 1;
  int cuts_ = 0;
};

}  // namespace angio
