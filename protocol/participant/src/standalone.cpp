#include "angio/participant/standalone.hpp"

#include <chrono>
#include <functional>

#include "angio/common/clock.hpp"
#include "angio/common/load_stepper.hpp"
#include "angio/common/log.hpp"

namespace angio::participant {
namespace {

std::string history(const SolveStats& s) { return "residual history " + log::list(s.residual_history); }

// The loop is the same for both roles; only the solve call differs.
int run(const scene::TimeSettings& time, const std::function<void(int, double)>& begin,
        const std::function<SolveStats()>& solve, const std::function<void(bool)>& end,
        const std::function<void()>& finish) {
  LoadStepper stepper(time);
  try {
    while (!stepper.finished()) {
      const auto t0 = Clock::now();
      begin(stepper.step(), stepper.time());
      SolveStats s = solve();
      if (!s.converged) {
        LOG_WARN("step " << stepper.step() << " t = " << stepper.time() << " s: not converged after " << s.iterations
                         << " iterations (" << s.message << "), " << history(s) << "; cutting the step");
        end(false);
        stepper.reject(s.message + ", " + history(s));
        continue;
      }
      end(true);
      const double wall = seconds_since(t0);
      // The participant logs its own line per committed step (with its physical measures).
      LOG_DEBUG("step " << stepper.step() << " t = " << stepper.time() << " s: " << s.iterations
                        << " Newton iterations, residual " << s.residual << ", " << wall << " s");
      stepper.accept(s.iterations);
    }
  } catch (const StepFailure& e) {
    LOG_ERROR(e.what());
    finish();
    return 3;
  }
  finish();
  return 0;
}

}  // namespace

int run_standalone(BeamParticipant& beam, const scene::TimeSettings& time) {
  return run(
      time, [&](int n, double t) { beam.begin_step(n, t); },
      [&] {
        const std::size_t n = beam.sample_points().size();
        return beam.solve(std::vector<Vec3>(n, Vec3{0.0, 0.0, 0.0}));
      },
      [&](bool a) { beam.end_step(a); }, [&] { beam.finish(); });
}

int run_standalone(SolidParticipant& solid, const scene::TimeSettings& time) {
  ContactReply reply;
  return run(
      time, [&](int n, double t) { solid.begin_step(n, t); }, [&] { return solid.solve(SamplePoints{}, reply, 0.0); },
      [&](bool a) { solid.end_step(a); }, [&] { solid.finish(); });
}

}  // namespace angio::participant
