// What the balloon/artery side must do to take part in a run, standalone or coupled (docs/design.md §3).
// solid_solver implements it (collectively on all MPI ranks); a replay participant from a recording.
#pragma once

#include "angio/participant/types.hpp"

namespace angio::participant {

class SolidParticipant {
 public:
  virtual ~SolidParticipant() = default;

  // Sets pressures etc. from the load curves at pseudo-time `time` (end of the step).
  virtual void begin_step(int step, double time) = 0;
  // Solves equilibrium with the beam sample points held fixed; fills the contact reply.
  // Empty `beam_points` means no stent. tolerance > 0: the absolute residual (N) the coupler allows
  // for this solve (inexact solves inside the coupling loop); 0: the participant's own tolerance.
  virtual SolveStats solve(const SamplePoints& beam_points, ContactReply& reply, double tolerance) = 0;
  // Interface Newton–Krylov (docs/design.md §5.5): how far each contact plane of the last solve's
  // reply moves along its normal (plane_shift, as that reply's planes) and how its normal turns
  // (normal_turn) when the sample points move by dx, linearized at the state that solve left (the
  // solid's tangent as last factorized). Nothing is solved anew or kept. Default: a failed stats
  // saying it is not supported.
  virtual SolveStats linear_response(const std::vector<Vec3>& dx, std::vector<double>& plane_shift,
                                     std::vector<Vec3>& normal_turn) {
    (void)dx;
    plane_shift.clear();
    normal_turn.clear();
    SolveStats s;
    s.message = "this solid participant has no linearized response (coupling.acceleration newton-krylov)";
    return s;
  }
  // accept: commit history and write output; reject: roll back to the last committed state.
  virtual void end_step(bool accept) = 0;
  virtual void finish() = 0;
};

}  // namespace angio::participant
