// What the stent side must do to take part in a run, standalone or coupled (docs/design.md §3).
// beam_solver implements it; a replay participant implements it from a recording.
#pragma once

#include "angio/participant/types.hpp"

namespace angio::participant {

class BeamParticipant {
 public:
  virtual ~BeamParticipant() = default;

  // Current positions, weights and radii of the contact sample points.
  virtual SamplePoints sample_points() const = 0;
  // Sets prescribed loads/supports from the load curves at pseudo-time `time` (end of the step).
  virtual void begin_step(int step, double time) = 0;
  // Solves equilibrium with the external contact line loads (N/mm) at the sample points, in
  // addition to the scene's own loads, starting from the current iterate.
  virtual SolveStats solve(const std::vector<Vec3>& line_loads) = 0;
  // Robin mode: as solve(), plus the penalty law of frozen contact planes at the sample points
  // (types.hpp ContactPlanes), linearized inside the beam's own Newton. Participants that cannot
  // do this keep this default, which reports a failed solve saying so.
  virtual SolveStats solve_with_planes(const std::vector<Vec3>& line_loads, const ContactPlanes& planes) {
    (void)line_loads;
    (void)planes;
    SolveStats s;
    s.message = "this beam participant does not support the robin coupling mode (contact planes)";
    return s;
  }
  // Interface Newton–Krylov (docs/design.md §5.5): the sample points' displacement dx (3 per point)
  // when plane j of the last solve_with_planes() moves by plane_shift[j] along its normal (mm) and its
  // normal turns by normal_turn[j] (perpendicular to it; empty: no turn), linearized at the state that
  // solve left: the beam's tangent with the planes' penalty. Nothing is solved anew or kept.
  // Participants that cannot do this keep this default (a failed stats saying so).
  virtual SolveStats linear_response(const std::vector<double>& plane_shift, const std::vector<Vec3>& normal_turn,
                                     std::vector<Vec3>& dx) {
    (void)plane_shift, (void)normal_turn;
    dx.clear();
    SolveStats s;
    s.message = "this beam participant has no linearized response (coupling.acceleration newton-krylov)";
    return s;
  }
  // accept: commit the plastic state and write output; reject: restore the last committed state.
  virtual void end_step(bool accept) = 0;
  // Close output files and write the summary.
  virtual void finish() = 0;
};

}  // namespace angio::participant
