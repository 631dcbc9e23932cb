#include "angio/common/load_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace angio {

LoadStepper::LoadStepper(const scene::TimeSettings& s)
    : s_(s), nominal_((s.end - s.start) / s.steps), t_(s.start), dt_(nominal_) {
  clamp_to_end();
}

// Lands exactly on the end time instead of leaving a sliver step.
void LoadStepper::clamp_to_end() {
  const double rest = s_.end - t_;
  if (dt_ > rest || rest - dt_ < 1e-9 * nominal_) dt_ = rest;
}

bool LoadStepper::finished() const { return s_.end - t_ <= 1e-9 * nominal_; }

void LoadStepper::accept() {
  t_ += dt_;
  ++step_;
  cuts_ = 0;
  dt_ = std::min(2.0 * dt_, nominal_);
  clamp_to_end();
}

void LoadStepper::reject(const std::string& reason) {
  ++cuts_;
  const double next = 0.5 * dt_;
  if (next < s_.min_step * (1.0 - 1e-12) || cuts_ > s_.max_cuts) {
    std::ostringstream os;
    os << "step " << step_ << " from t = " << t_ << " s failed with increment " << dt_
       << " s and cannot be cut further (time.min_step = " << s_.min_step
       << " s, time.max_cuts = " << s_.max_cuts << "): " << reason;
    throw StepFailure(os.str());
  }
  dt_ = next;
}

}  // namespace angio
