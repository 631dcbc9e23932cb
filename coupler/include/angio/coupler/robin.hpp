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
//
// Surface compliance (optional): a plane with penalty ε in front of a soft surface (the artery wall,
// a pressurized balloon) tells the beam that the contact is as stiff as the penalty, while the
// surface gives way behind it. A strut pressed between two soft surfaces then moves by only about
// (k_a + k_b)/(2ε) of its error per iteration (k the surfaces' stiffness per unit length, ~0.1
// N/mm² for the wall against ε = 10): the struts creep into the wall over many iterations. With
// `surface_compliance` each plane j carries an estimate k_j of its surface's stiffness against its
// own load (the secant −Δf_j/Δd_j of its force and its offset along the normal between the first
// and the last coupling iteration of an accepted step, smoothed over steps), and the iterate is the
// series spring of penalty and surface, ε' = ε k/(ε + k), at the unloaded surface (the reply's plane
// moved along n so that at the beam's positions it carries the reply's load). A plane whose load
// never changed enough for a secant of its own takes its surface's median estimate (a wall that
// bears on struts where the balloon does not press would otherwise keep the bare penalty). The beam then sees
// the interface's tangent in this diagonal model; the map stays a function of the iterate (IQN's
// secants hold) and at the fixed point both laws carry the solid's load.
//
// With an acceleration that takes the map's Jacobian (newton-krylov) the planes' normals are
// unknowns as well (the iterate is the points, then the normals): the solid turns them as its
// surface deforms, the beam answers a turn with its soft sliding modes, and taken from the last
// reply as they are they converge only by plain substitution (docs/design.md §5.5).
#pragma once

#include <vector>

#include "angio/coupler/interface_scheme.hpp"

namespace angio::coupler {

class Robin : public InterfaceScheme {
 public:
  Robin(std::size_t n_points, bool surface_compliance);
  void begin_step(double increment, bool extrapolate) override;
  participant::SolveStats solve_beam(participant::BeamParticipant& beam) override;
  Eigen::VectorXd force_residual(const participant::SamplePoints& x, const participant::ContactReply& reply) override;
  void next_iterate(Acceleration& acc, int k) override;
  Eigen::VectorXd map_derivative(participant::BeamParticipant& beam, participant::SolidParticipant& solid,
                                 const Eigen::VectorXd& v) override;
  void accept(double increment) override;
  void reject() override;

 private:
  struct Planes {
    Eigen::VectorXd s, n, eps;  // 3Kn, 3Kn, Kn (plane j of point i at i·K + j)
    double g0 = 0.0;            // regularization of the penalty law (mm)
  };
  // Sets the number of planes per point from the solid's first reply (fixed for a run).
  void set_planes_per_point_(std::size_t K);
  std::size_t n_ = 0, K_ = 1;
  // Forces (N/mm, along n) of the planes p at positions x (the penalty law of plane_penalty.hpp).
  static Eigen::VectorXd plane_forces(const participant::SamplePoints& x, const Planes& p);
  // Σ line loads f_j n_j of the planes with forces f per point (N/mm, 3 per point).
  static Eigen::VectorXd loads_of(const Planes& p, const Eigen::VectorXd& f, std::size_t n_points);
  // With surface compliance: the planes p (forces f at x) as series springs of penalty and surface
  // at the unloaded surface, each with stiffness_(j); planes with none stay as they are.
  Planes softened_(const participant::SamplePoints& x, const Planes& p, const Eigen::VectorXd& f) const;
  // The stiffness plane j is softened with: its own estimate within a decade of its surface's
  // median, the median where it has none; 0 (not softened) before a surface has a median.
  double stiffness_(Eigen::Index j) const;
  // Surface stiffness per plane from this step's first and last replies (secant), at accept.
  void update_stiffness_();
  // p_tilde_: the last reply as an iterate (softened with surface compliance), reply_: as the solid
  // sent it; first_: the step's first reply (for the secant).
  Planes p_, p_tilde_, p_last_, p_before_, reply_, first_, accepted_reply_;
  bool compliance_ = false;
  Eigen::VectorXd k_;                                  // per plane: surface stiffness estimate (N/mm²), 0 unknown
  std::vector<double> k_surface_;                      // per contact surface: median of k_ (planes without their own)
  std::vector<bool> softened_last_, softened_before_;  // per plane: p_last_ / p_before_ a softened plane
  // fewer estimates than this on a surface: no median (one plane's secant is noise, not a surface)
  static constexpr std::size_t min_estimates_for_median = 10;
  Eigen::VectorXd f_first_, f_reply_;  // plane forces of first_ and reply_
  Eigen::VectorXd f_previous_;         // plane forces of the reply before (the debug log's switches)
  participant::SamplePoints x_;        // positions of the last reply
  bool have_first_ = false;
  Eigen::VectorXd c_, c_tilde_, c_last_;  // remainder loads (two surfaces at one point)
  double dt_last_ = 0.0;
};

}  // namespace angio::coupler
