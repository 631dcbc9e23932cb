// Dirichlet–Neumann on the contact line loads (docs/design.md §5.2): q_k in, q~_k out.
#include "angio/coupler/dirichlet_neumann.hpp"

#include "interface_vectors.hpp"

namespace angio::coupler {

DirichletNeumann::DirichletNeumann(std::size_t n)
    : q_(Eigen::VectorXd::Zero(3 * n)), q_last_(q_), q_before_(q_), q_tilde_(q_), r_(q_) {}

void DirichletNeumann::begin_step(double increment, bool extrapolate) {
  q_ = q_last_;
  if (extrapolate && dt_last_ > 0.0) q_ += (increment / dt_last_) * (q_last_ - q_before_);
}

participant::SolveStats DirichletNeumann::solve_beam(participant::BeamParticipant& beam) {
  return beam.solve(unflatten(q_));
}

Eigen::VectorXd DirichletNeumann::force_residual(const participant::SamplePoints&,
                                                 const participant::ContactReply& reply) {
  q_tilde_ = flatten(reply.line_loads);
  r_ = q_tilde_ - q_;
  return r_;
}

void DirichletNeumann::next_iterate(Acceleration& acc, int k) { q_ = acc.update(q_, r_, k); }

void DirichletNeumann::accept(double increment) {
  // The solid state belongs to x_k, and q~_k is the load consistent with it.
  q_before_ = q_last_;
  q_last_ = q_tilde_;
  dt_last_ = increment;
}

}  // namespace angio::coupler
