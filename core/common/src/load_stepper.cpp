#include "angio/common/load_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace angio {

LoadStepper::LoadStepper(const scene::TimeSettings& s)
    : s_(s), nominal_((s.end - s.start) / s.steps), t_(s.start), dt_(nominal_) {
  clamp_to_grid();
}

// Never steps across a point of the nominal grid (start + k·Δt_nominal): after a cut the
// increments grow back but still land on the grid, so the corners of the load curves (the peak
// pressure at t = 1 s) are hit exactly. Also lands exactly on the end time.
// Larger (adaptive) steps land on the grid point at or below t + dt. Never across a stop either.
void LoadStepper::clamp_to_grid() {
  const double tol = 1e-9 * nominal_;
  double k = std::floor((t_ - s_.start) / nominal_ + 1e-9) + 1.0;
  if (dt_ > nominal_ + tol) k = std::max(k, std::floor((t_ + dt_ - s_.start) / nominal_ + 1e-9));
  double next = std::min(s_.start + k * nominal_, s_.end);
  const auto stop = std::upper_bound(s_.stops.begin(), s_.stops.end(), t_ + tol);
  if (stop != s_.stops.end()) next = std::min(next, *stop);
  const double rest = next - t_;
  if (dt_ > rest || rest - dt_ < tol) dt_ = rest;
}

bool LoadStepper::finished() const { return s_.end - t_ <= 1e-9 * nominal_; }

void LoadStepper::accept(int iterations) {
  const bool full = dt_ >= nominal_ * (1.0 - 1e-9);
  t_ += dt_;
  ++step_;
  cuts_ = 0;
  const bool grow = s_.max_step > 0.0 && full && iterations <= s_.easy_iterations;
  dt_ = grow ? std::min(2.0 * dt_, s_.max_step) : std::min(2.0 * dt_, nominal_);
  clamp_to_grid();
}

void LoadStepper::reject(const std::string& reason) {
  ++cuts_;
  const double next = 0.5 * dt_;
  if (next < s_.min_step * (1.0 - 1e-12) || cuts_ > s_.max_cuts) {
    std::ostringstream os;
    os << "step " << step_ << " from t = " << t_ << " s failed with increment " << dt_
       << " s and cannot be cut further (time.min_step = " << s_.min_step << " s, time.max_cuts = " << s_.max_cuts
       << "): " << reason;
    throw StepFailure(os.str());
  }
  dt_ = next;
}

}  // namespace angio
