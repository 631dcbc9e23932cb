// What is iterated at the stent–solid interface within a load step (docs/design.md §5.2):
//  - dirichlet-neumann: the contact line loads q; the beam takes q, the solid returns q~.
//  - robin: the solid's contact planes (point s, normal n, penalty ε per sample point); the beam
//    takes the planes and applies their penalty law q(x) = −ε⟨(x − s)·n − R⟩n inside its own
//    Newton, the solid returns the planes at the beam's new positions. The beam then "sees" the
//    penalty stiffness, which the plain Dirichlet–Neumann iteration hides from it: the stiff
//    short-wave modes (struts indenting the balloon) that make Dirichlet–Neumann need tiny
//    relaxation factors converge by themselves, only the soft global mode is left to Aitken.
// Both are judged by the same force residual q~ − q_beam (the solid's contact load minus the load
// the beam applied), so tolerances mean the same in both schemes.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "angio/coupler/acceleration.hpp"
#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"

namespace angio::coupler {

class InterfaceScheme {
 public:
  virtual ~InterfaceScheme() = default;
  // First iterate of a step from the accepted steps before (constant or linear extrapolation
  // with the ratio of the step increments).
  virtual void begin_step(double increment, bool extrapolate) = 0;
  // Beam solve with the current iterate.
  virtual participant::SolveStats solve_beam(participant::BeamParticipant& beam) = 0;
  // The solid's reply for the beam's positions x: returns the force residual q~ − q_beam (N/mm,
  // 3 per point) and keeps what next_iterate() needs. q~ is reply.line_loads.
  virtual Eigen::VectorXd force_residual(const participant::SamplePoints& x,
                                         const participant::ContactReply& reply) = 0;
  // Next iterate through the acceleration (iteration k of the step, 0-based).
  virtual void next_iterate(Acceleration& acc, int k) = 0;
  // The derivative of the map (iterate -> the solid's reply as an iterate) along v at the last
  // iterate, from the participants' linearized responses at their last solves (newton-krylov; called
  // by the acceleration inside next_iterate(), with v shaped as the iterate it passes). Empty when a
  // participant cannot linearize or the scheme has no such derivative.
  virtual Eigen::VectorXd map_derivative(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                                         const Eigen::VectorXd& v) {
    (void)beam, (void)solid, (void)v;
    return {};
  }
  // The step was accepted with the last force_residual(): remember the converged state.
  virtual void accept(double increment) = 0;
  // The step was rejected and will be cut (its attempt is tried again from the accepted state).
  virtual void reject() {}
  // The converged state of an earlier run, from the solid's reply at the beam's committed positions
  // x: taken as the accepted state of the step before the first (no extrapolation from it).
  void seed(const participant::SamplePoints& x, const participant::ContactReply& reply) {
    force_residual(x, reply);
    accept(0.0);
  }
};

std::unique_ptr<InterfaceScheme> make_interface_scheme(const std::string& name, std::size_t n_points,
                                                       bool surface_compliance);

}  // namespace angio::coupler
