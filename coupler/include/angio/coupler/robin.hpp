// Robin coupling (docs/design.md §5.3): the iterate is the set of frozen contact planes the
// solid reports per sample point (point s, unit normal n toward the beam, penalty ε). The beam
// adds their penalty law q(x) = −ε⟨(x − s)·n − R⟩n to its loads and linearizes it in its Newton
// (participant/plane_penalty.hpp); the solid evaluates the true contact at the beam's positions
// and returns the planes there. The acceleration acts on the plane points, moved only along the
// normal (the tangential position of s does not change the plane). K planes per point, one per
// contact surface (balloon and artery: a strut pressed between them sees the stiffness of both;
// with a single plane the other surface's load would be a fixed Neumann load for the soft stent,
// and the iteration oscillates as in plain Dirichlet–Neumann). The remainder q~ − Σ q_plane(x) of
// the solid's load (zero when the planes represent the contact exactly) is passed to the beam as a
// fixed line load, so the fixed point is exact in any case.
#pragma once

#include "angio/coupler/interface_scheme.hpp"

namespace angio::coupler {

class Robin : public InterfaceScheme {
 public:
  explicit Robin(std::size_t n_points);
  void begin_step(double increment, bool extrapolate) override;
  participant::SolveStats solve_beam(participant::BeamParticipant& beam) override;
  Eigen::VectorXd force_residual(const participant::SamplePoints& x, const participant::ContactReply& reply) override;
  void next_iterate(Acceleration& acc, int k) override;
  void accept(double increment) override;

 private:
  struct Planes {
    Eigen::VectorXd s, n, eps;  // 3Kn, 3Kn, Kn (plane j of point i at i·K + j)
    double g0 = 0.0;            // regularization of the penalty law (mm)
  };
  // Sets the number of planes per point from the solid's first reply (fixed for a run).
  void set_planes_per_point_(std::size_t K);
  std::size_t n_ = 0, K_ = 1;
  // Σ line loads of the planes at positions x (N/mm, 3 per point).
  static Eigen::VectorXd plane_loads(const participant::SamplePoints& x, const Planes& p);
  Planes p_, p_tilde_, p_last_, p_before_;
  Eigen::VectorXd c_, c_tilde_, c_last_;  // remainder loads (two surfaces at one point)
  double dt_last_ = 0.0;
};

}  // namespace angio::coupler
