// Dirichlet–Neumann on the contact line loads q (docs/design.md §5.2): the beam is the Neumann side (q in,
// positions out), the solid the Dirichlet side (positions in, q~ out); acceleration acts on q.
#pragma once

#include "angio/coupler/interface_scheme.hpp"

namespace angio::coupler {

class DirichletNeumann : public InterfaceScheme {
 public:
  explicit DirichletNeumann(std::size_t n_points);
  void begin_step(double increment, bool extrapolate) override;
  participant::SolveStats solve_beam(participant::BeamParticipant& beam) override;
  Eigen::VectorXd force_residual(const participant::SamplePoints& x, const participant::ContactReply& reply) override;
  void next_iterate(Acceleration& acc, int k) override;
  void accept(double increment) override;

 private:
  Eigen::VectorXd q_, q_last_, q_before_, q_tilde_, r_;
  double dt_last_ = 0.0;
};

}  // namespace angio::coupler
