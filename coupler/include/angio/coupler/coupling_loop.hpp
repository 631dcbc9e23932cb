// The staggered Dirichlet–Neumann (Gauss–Seidel) coupling of the beam and the solid per load
// step, with acceleration, step acceptance/rejection and step cutting (docs/design.md §5.2 and §6, paper §3).
// Written against the participant interfaces: the same loop drives remote processes and
// in-process participants (tests).
#pragma once

#include <functional>
#include <stdexcept>
#include <vector>

#include "angio/common/load_stepper.hpp"
#include "angio/coupler/acceleration.hpp"
#include "angio/coupler/coupling_settings.hpp"
#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"

namespace angio::coupler {

struct StepReport {
  int step = 0;
  double time = 0.0;
  int iterations = 0;             // coupling iterations of the accepted attempt
  std::vector<double> residuals;  // ||r_k|| per iteration of that attempt
  double omega = 0.0;             // last relaxation factor
  int cuts = 0;                   // rejected attempts before acceptance
  int restarts = 0;               // acceleration restarts in the accepted attempt (restart_growth)
  bool converged = true;          // false: accepted with a warning (strict: false)
  double beam_time = 0.0;         // s in beam solves (incl. messaging when remote)
  double solid_time = 0.0;        // s in solid solves (incl. messaging when remote)
  double wall_time = 0.0;         // s for the whole step incl. rejected attempts
  int products = 0;               // newton-krylov: Jacobian-vector products of the accepted attempt
  double product_time = 0.0;      // s in them (both participants' linearized responses and messaging)
  participant::ContactReply contact;
  participant::SamplePoints beam_points;
};

struct RunReport {
  int steps = 0;
  int total_iterations = 0;
  double mean_iterations() const { return steps ? double(total_iterations) / steps : 0.0; }
  int max_iterations = 0;
  int rejected_attempts = 0;
  int prediction_retries = 0;  // steps retried from the last accepted state after the extrapolated start failed
  double wall_time = 0.0;
  // s in solves over every attempt, rejected steps included
  double beam_time = 0.0;
  double solid_time = 0.0;
  long products = 0;          // newton-krylov: Jacobian-vector products, every attempt
  double product_time = 0.0;  // s in them
  bool interrupted = false;   // stopped after a committed step at the callback's request (StopRequested)
};

// Thrown by a StepCallback to stop the run after the step it was called for (committed): run_coupled
// returns its report with `interrupted` set instead of going on (e.g. Ctrl-C: everything written so
// far stays consistent, and the participants can still be shut down normally).
struct StopRequested {};

using StepCallback = std::function<void(const StepReport&)>;

// Runs all load steps. Throws StepFailure (step, time, residual history) when a step cannot be
// completed even at the minimum increment; participants have rolled back to their last committed
// state by then, so everything written so far stays consistent.
RunReport run_coupled(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                      const scene::TimeSettings& time, const CouplingSettings& settings, Acceleration& acceleration,
                      const StepCallback& on_step = {});

}  // namespace angio::coupler
