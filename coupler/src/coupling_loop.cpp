#include "angio/coupler/coupling_loop.hpp"

#include <cmath>
#include <limits>

#include "angio/common/clock.hpp"
#include "angio/common/log.hpp"
#include "angio/coupler/interface_scheme.hpp"

namespace angio::coupler {
namespace {

std::string newton_failure(const char* who, int k, const participant::SolveStats& s) {
  return std::string(who) + " Newton failed in coupling iteration " + std::to_string(k) + ": " + s.message +
         ", residual history " + log::list(s.residual_history);
}

// |w r| (N): the coupling residual r (N/mm per sample point, 3 per point) weighted by the arc lengths.
double weighted_norm(const Eigen::VectorXd& r, const std::vector<double>& w) {
  double s = 0.0;
  for (std::size_t i = 0; i < w.size() && 3 * i + 2 < std::size_t(r.size()); ++i)
    s += w[i] * w[i] * r.segment<3>(3 * i).squaredNorm();
  return std::sqrt(s);
}

}  // namespace

RunReport run_coupled(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                      const scene::TimeSettings& time, const CouplingSettings& settings, Acceleration& acc,
                      const StepCallback& on_step) {
  LoadStepper stepper(time);
  RunReport run;
  const auto run_start = Clock::now();
  const std::size_t n = beam.sample_points().size();
  const double sqrt_len = std::sqrt(static_cast<double>(3 * n));
  auto scheme = make_interface_scheme(settings.scheme, n, settings.surface_compliance);

  double first_residual_force = 0.0;  // |w r_0| of the last accepted step (N): iteration 0's solid tolerance
  if (settings.synchronize) {
    // A run continued from state files: the contact planes (loads) of the committed state are not in
    // any file; the solid recomputes them at the beam's committed positions at the start time,
    // without a Newton iteration (the largest tolerance: the committed state is an equilibrium) and
    // without committing, so the first step starts from them instead of from a stent without contact.
    const auto points = beam.sample_points();
    participant::ContactReply reply;
    solid.begin_step(stepper.step() - 1, time.start);
    const participant::SolveStats ss = solid.solve(points, reply, std::numeric_limits<double>::max());
    solid.end_step(false);
    if (!ss.converged || reply.line_loads.size() != n)
      throw std::runtime_error("the solid's contact state at the start time could not be evaluated: " + ss.message);
    scheme->seed(points, reply);
    LOG_INFO("interface state recomputed at t = " << time.start << " s from the participants' committed states");
  }
  // newton-krylov: products of the map's Jacobian through the participants' linearizations
  int products = 0;
  double product_time = 0.0;
  if (acc.uses_jacobian())
    acc.set_jacobian([&](const Eigen::VectorXd& v) {
      const auto t0 = Clock::now();
      Eigen::VectorXd jv = scheme->map_derivative(beam, solid, v);
      ++products;
      product_time += seconds_since(t0);
      return jv;
    });
  auto step_start = Clock::now();
  // A step whose first coupling iteration fails in a participant from the extrapolated iterate (e.g.
  // the extrapolated contact planes push struts into the wall and the beam's or the solid's Newton
  // fails) is tried once more from the last accepted interface state before it is cut: the
  // extrapolation, not the increment, was what failed. Its cuts, if it fails again, start from the
  // last accepted state too (a hopeless step pays one extra attempt, not one per cut).
  bool constant_retry = false;
  while (!stepper.finished()) {
    StepReport rep;
    rep.step = stepper.step();
    rep.time = stepper.time();
    rep.cuts = stepper.cuts();
    beam.begin_step(rep.step, rep.time);
    solid.begin_step(rep.step, rep.time);
    acc.begin_step();

    const bool extrapolate = settings.prediction == "extrapolate" && !constant_retry;
    scheme->begin_step(stepper.increment(), extrapolate);
    int failed_at = -1;  // coupling iteration of a participant failure

    bool converged = false, participant_failed = false;
    std::string failure;
    double smallest = std::numeric_limits<double>::infinity();  // residual, since the last restart
    int k_restart = 0;  // iteration of the last restart: the acceleration counts from there
    // Stall guard: the residual of the last iteration that halved the mark before it. A step whose
    // residual has not halved in stall_iterations iterations contracts so slowly that max_iterations
    // of them reduce it by 2^(max_iterations / stall_iterations) at most (about tenfold with the
    // declared defaults), less than a step needs; the cut step is cheaper than the wait.
    double mark = std::numeric_limits<double>::infinity();
    int k_mark = 0;
    bool stalled = false;
    double solid_tolerance = settings.inexact_solid * first_residual_force;
    double step_first_force = 0.0;
    for (int k = 0; k < settings.max_iterations; ++k) {
      auto t0 = Clock::now();
      participant::SolveStats bs = scheme->solve_beam(beam);
      rep.beam_time += seconds_since(t0);
      if (!bs.converged) {
        participant_failed = true;
        failed_at = k;
        failure = newton_failure("beam", k, bs);
        break;
      }
      rep.beam_points = beam.sample_points();
      t0 = Clock::now();
      participant::SolveStats ss = solid.solve(rep.beam_points, rep.contact, solid_tolerance);  // positions in
      rep.solid_time += seconds_since(t0);
      if (!ss.converged) {
        participant_failed = true;
        failed_at = k;
        failure = newton_failure("solid", k, ss);
        break;
      }
      const auto& reply = rep.contact;
      if (reply.line_loads.size() != n)
        throw std::runtime_error("solid returned " + std::to_string(reply.line_loads.size()) + " line loads for " +
                                 std::to_string(n) + " sample points");
      const Eigen::VectorXd r = scheme->force_residual(rep.beam_points, reply);
      if (!r.allFinite()) {
        participant_failed = true;
        failure = "solid returned non-finite contact line loads or planes";
        break;
      }
      double q_norm = 0.0;
      for (const auto& q : reply.line_loads) q_norm += q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
      q_norm = std::sqrt(q_norm);
      const double rn = r.norm();
      const double r_force = weighted_norm(r, rep.beam_points.w);
      if (k == 0) step_first_force = r_force;
      solid_tolerance = settings.inexact_solid * r_force;
      rep.residuals.push_back(rn);
      rep.iterations = k + 1;
      LOG_DEBUG("step " << rep.step << " iteration " << k << ": ||r|| = " << rn << ", ||q~|| = " << q_norm
                        << ", omega = " << acc.last_factor());
      if (rn <= settings.rel_tol * q_norm + settings.abs_tol * sqrt_len) {
        converged = true;
        break;
      }
      // A residual far above the smallest of the step means the acceleration's model has turned
      // against the map (IQN-ILS columns from another contact state): drop it and restart from
      // the current iterate (columns of earlier steps too) instead of following it to max_iterations.
      if (settings.restart_growth > 0.0 && rn > settings.restart_growth * smallest) {
        LOG_DEBUG("step " << rep.step << " iteration " << k << ": residual " << rn << " > " << settings.restart_growth
                          << " x " << smallest << ", acceleration restarted");
        acc.restart();
        ++rep.restarts;
        k_restart = k;
        smallest = rn;
      }
      smallest = std::min(smallest, rn);
      if (rn < 0.5 * mark) {
        mark = rn;
        k_mark = k;
      } else if (settings.stall_iterations > 0 && k - k_mark >= settings.stall_iterations) {
        stalled = true;
        break;
      }
      const int products_before = products;
      const double product_time_before = product_time;
      scheme->next_iterate(acc, k - k_restart);
      rep.omega = acc.last_factor();
      rep.products += products - products_before;
      rep.product_time += product_time - product_time_before;
    }

    run.beam_time += rep.beam_time;  // every attempt: a rejected one cost its solves too
    run.solid_time += rep.solid_time;
    run.products += rep.products;
    run.product_time += rep.product_time;
    const bool accept = converged || (!participant_failed && !settings.strict && rep.iterations > 0);
    if (!accept && failed_at == 0 && extrapolate) {
      LOG_INFO("step " << rep.step << " t = " << rep.time << " s: " << failure
                       << "; retrying the step from the last accepted interface state (no extrapolation)");
      beam.end_step(false);
      solid.end_step(false);
      acc.end_step(false);
      ++run.prediction_retries;
      constant_retry = true;
      continue;  // the same step again, not cut
    }
    if (!accept) {
      if (!participant_failed)
        failure =
            (stalled ? "coupling stalled (the residual of iteration " + std::to_string(k_mark) + " not halved in " +
                           std::to_string(settings.stall_iterations) + " iterations)"
                     : "coupling did not converge in " + std::to_string(settings.max_iterations) + " iterations") +
            ", residual history " + log::list(rep.residuals);
      LOG_WARN("step " << rep.step << " t = " << rep.time << " s rejected: " << failure << "; cutting the step");
      beam.end_step(false);
      solid.end_step(false);
      acc.end_step(false);
      scheme->reject();
      ++run.rejected_attempts;
      stepper.reject(failure);  // throws StepFailure below the minimum increment
      continue;
    }
    if (!converged)
      LOG_WARN("step " << rep.step << ": coupling " << (stalled ? "stalled, not converged" : "not converged")
                       << " after " << rep.iterations << " iterations (residual " << rep.residuals.back()
                       << "), accepted because coupling.strict is false");
    rep.converged = converged;
    constant_retry = false;
    first_residual_force = step_first_force;
    beam.end_step(true);
    solid.end_step(true);
    acc.end_step(true);
    scheme->accept(stepper.increment());
    rep.omega = acc.last_factor();
    rep.wall_time = seconds_since(step_start);
    run.steps++;
    run.total_iterations += rep.iterations;
    run.max_iterations = std::max(run.max_iterations, rep.iterations);
    if (on_step) {
      try {
        on_step(rep);
      } catch (const StopRequested&) {
        run.interrupted = true;
        break;
      }
    }
    stepper.accept(rep.iterations);
    step_start = Clock::now();
  }
  run.wall_time = seconds_since(run_start);
  return run;
}

}  // namespace angio::coupler
