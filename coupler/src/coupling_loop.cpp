#include "angio/coupler/coupling_loop.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include "angio/common/log.hpp"

namespace angio::coupler {
namespace {

using Clock = std::chrono::steady_clock;
using participant::Vec3;

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Eigen::VectorXd flatten(const std::vector<Vec3>& v) {
  Eigen::VectorXd out(3 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) out[3 * i + d] = v[i][d];
  return out;
}

std::vector<Vec3> unflatten(const Eigen::VectorXd& x) {
  std::vector<Vec3> out(x.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
  return out;
}

std::string history(const std::vector<double>& h) {
  std::ostringstream os;
  os << "[";
  for (std::size_t i = 0; i < h.size(); ++i) os << (i ? ", " : "") << h[i];
  return os.str() + "]";
}

}  // namespace

RunReport run_coupled(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                      const scene::TimeSettings& time, const CouplingSettings& settings,
                      Acceleration& acc, const StepCallback& on_step) {
  LoadStepper stepper(time);
  RunReport run;
  const auto run_start = Clock::now();
  const std::size_t n = beam.sample_points().size();
  const double sqrt_len = std::sqrt(static_cast<double>(3 * n));
  // Converged interface loads of the last two steps, for the prediction of the first iterate.
  Eigen::VectorXd q_last = Eigen::VectorXd::Zero(3 * n), q_before = q_last;
  double dt_last = 0.0;

  auto step_start = Clock::now();
  while (!stepper.finished()) {
    StepReport rep;
    rep.step = stepper.step();
    rep.time = stepper.time();
    rep.cuts = stepper.cuts();
    beam.begin_step(rep.step, rep.time);
    solid.begin_step(rep.step, rep.time);
    acc.begin_step();

    Eigen::VectorXd q = q_last;
    if (settings.prediction == "extrapolate" && dt_last > 0.0)
      q += (stepper.increment() / dt_last) * (q_last - q_before);

    bool converged = false, participant_failed = false;
    std::string failure;
    for (int k = 0; k < settings.max_iterations; ++k) {
      auto t0 = Clock::now();
      participant::SolveStats bs = beam.solve(unflatten(q));  // Neumann: loads in, positions out
      rep.beam_time += since(t0);
      if (!bs.converged) {
        participant_failed = true;
        failure = "beam Newton failed in coupling iteration " + std::to_string(k) + ": " +
                  bs.message + ", residual history " + history(bs.residual_history);
        break;
      }
      rep.beam_points = beam.sample_points();
      t0 = Clock::now();
      participant::SolveStats ss = solid.solve(rep.beam_points, rep.contact);  // Dirichlet
      rep.solid_time += since(t0);
      if (!ss.converged) {
        participant_failed = true;
        failure = "solid Newton failed in coupling iteration " + std::to_string(k) + ": " +
                  ss.message + ", residual history " + history(ss.residual_history);
        break;
      }
      const Eigen::VectorXd q_tilde = flatten(rep.contact.line_loads);
      if (q_tilde.size() != q.size())
        throw std::runtime_error("solid returned " + std::to_string(q_tilde.size() / 3) +
                                 " line loads for " + std::to_string(n) + " sample points");
      if (!q_tilde.allFinite()) {
        participant_failed = true;
        failure = "solid returned non-finite contact line loads";
        break;
      }
      const Eigen::VectorXd r = q_tilde - q;
      const double rn = r.norm();
      rep.residuals.push_back(rn);
      rep.iterations = k + 1;
      LOG_DEBUG("step " << rep.step << " iteration " << k << ": ||r|| = " << rn << ", ||q~|| = "
                        << q_tilde.norm() << ", omega = " << acc.last_factor());
      if (rn <= settings.rel_tol * q_tilde.norm() + settings.abs_tol * sqrt_len) {
        converged = true;
        // The solid state corresponds to x_k, and q~_k is the consistent load for it; the beam
        // was solved with q_k, which agrees with q~_k to tolerance.
        q = q_tilde;
        break;
      }
      q = acc.update(q, r, k);
      rep.omega = acc.last_factor();
    }

    const bool accept =
        converged || (!participant_failed && !settings.strict && rep.iterations > 0);
    if (!accept) {
      if (!participant_failed)
        failure = "coupling did not converge in " + std::to_string(settings.max_iterations) +
                  " iterations, residual history " + history(rep.residuals);
      LOG_WARN("step " << rep.step << " t = " << rep.time << " s rejected: " << failure
                       << "; cutting the step");
      beam.end_step(false);
      solid.end_step(false);
      acc.end_step(false);
      ++run.rejected_attempts;
      stepper.reject(failure);  // throws StepFailure below the minimum increment
      continue;
    }
    if (!converged)
      LOG_WARN("step " << rep.step << ": coupling not converged after " << rep.iterations
                       << " iterations (residual " << rep.residuals.back()
                       << "), accepted because coupling.strict is false");
    rep.converged = converged;
    beam.end_step(true);
    solid.end_step(true);
    acc.end_step(true);
    q_before = q_last;
    q_last = q;
    dt_last = stepper.increment();
    rep.omega = acc.last_factor();
    rep.wall_time = since(step_start);
    run.steps++;
    run.total_iterations += rep.iterations;
    run.max_iterations = std::max(run.max_iterations, rep.iterations);
    run.beam_time += rep.beam_time;
    run.solid_time += rep.solid_time;
    if (on_step) on_step(rep);
    stepper.accept();
    step_start = Clock::now();
  }
  run.wall_time = since(run_start);
  return run;
}

}  // namespace angio::coupler
