// Beam structure: nodes (6 DOFs: position + rotation), Simo–Reissner elements, supports, loads,
// the Newton solver and the committed/trial state. Independent of the scene format and of the
// co-simulation: scene.cpp builds a BeamModel, participant.cpp drives it.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "angio/beam/element.hpp"
#include "angio/beam/linear_solver.hpp"
#include "angio/scene/keys_generated.hpp"

namespace angio::beam {

using Curve = std::function<double(double)>;  // load curve of pseudo-time (s)
inline Curve constant_curve(double v = 1.0) {
  return [v](double) { return v; };
}

// Device axis: a polyline (2 points = straight axis, extended beyond its ends).
struct Axis {
  std::vector<Vec3> points{Vec3::Zero(), Vec3::UnitZ()};
  struct Projection {
    Vec3 foot;     // closest point on the axis
    Vec3 tangent;  // unit axis direction there
    Vec3 radial;   // unit radial direction (x − foot, normalized)
    double r = 0;  // radial distance
    double s = 0;  // arc length of the foot along the axis
  };
  Projection project(const Vec3& x) const;
};

struct NodalLoad {
  int node;
  Vec3 force = Vec3::Zero();   // N, fixed in space
  Vec3 moment = Vec3::Zero();  // N mm, fixed in space
  Curve curve = constant_curve();
};
struct LineLoad {             // uniform distributed force per reference length (N/mm), fixed in space
  std::vector<int> elements;  // empty: all
  Vec3 q = Vec3::Zero();
  Curve curve = constant_curve();
};
// Radial line load w.r.t. the device axis, magnitude p (N/mm of reference length).
// follower = false (default): direction = radial direction of the sample point in the reference
// configuration (dead load). follower = true: current radial direction w.r.t. the fixed axis;
// note that this load destabilizes lateral motion of a ring off the axis (its resultant grows
// with the offset), which makes load-controlled plastic expansion unstable.
struct RadialLineLoad {
  std::vector<int> elements;  // empty: all
  double p = 0;
  Curve curve = constant_curve();
  bool follower = false;
};
struct PrescribedDisplacement {  // local component `comp` of node's basis: u·b_comp = value·curve(t)
  int node, comp;
  double value;
  Curve curve = constant_curve();
};
struct PrescribedRotation {  // node rotation R = exp(value·curve(t)); all rotations of node fixed
  int node;
  Vec3 value;
  Curve curve = constant_curve();
};

struct NewtonOptions {
  // the scene's stent.solver keys (core/scene/keys.yaml): meaning and defaults there
  int max_iterations = scene::keys::defaults::stent_solver_max_iterations;
  double residual_tol = scene::keys::defaults::stent_solver_residual_tol;          // N
  double residual_rel_tol = scene::keys::defaults::stent_solver_residual_rel_tol;  // of the first residual
  double increment_tol = scene::keys::defaults::stent_solver_increment_tol;        // mm, rad
  // Backtracking (energy-norm criterion) on every iteration; off by default because the
  // plain Newton step converges faster for beams. NaN/Inf always triggers backtracking.
  bool line_search = scene::keys::defaults::stent_solver_line_search;
  int max_line_search = 6;
  std::string linear_solver = scene::keys::defaults::stent_solver_linear_solver;
};

struct NewtonStats {
  bool converged = false;
  int iterations = 0;
  double residual = 0;
  std::vector<double> residual_history;
  std::vector<double> increment_history;
  std::string message;
  double seconds = 0;
};

class BeamModel {
 public:
  // ---- definition (call before finalize()) ----
  int add_node(const Vec3& X);
  // Element with reference triads O1, O2 at its nodes (default: triad_from_tangent(X2−X1, up)).
  int add_element(int n1, int n2, int section, const Vec3& up = Vec3::Zero());
  int add_element(int n1, int n2, int section, const Quat& O1, const Quat& O2);
  int add_section(const Section& s);

  // Supports: `fixed` = {ux,uy,uz,rx,ry,rz} in the node's basis (columns: local directions).
  void fix(int node, const std::array<bool, 6>& fixed);
  // Fixation w.r.t. the axis: the node's translation basis becomes (radial, circumferential,
  // axial). Radial and circumferential fixation throw std::invalid_argument for a node on the axis.
  // Only radial motion (circumferential + axial translations fixed).
  void fix_radial_only(int node) { fix_cylindrical(node, true, true); }
  // Only the axial translation fixed.
  void fix_axial(int node) { fix_cylindrical(node, false, true); }
  // Only the circumferential translation fixed.
  void fix_circumferential(int node) { fix_cylindrical(node, true, false); }

  Axis axis;
  std::vector<NodalLoad> nodal_loads;
  std::vector<LineLoad> line_loads;
  std::vector<RadialLineLoad> radial_loads;
  std::vector<PrescribedDisplacement> prescribed_displacements;
  std::vector<PrescribedRotation> prescribed_rotations;
  NewtonOptions newton;
  // Variational form of the element residuals (element.hpp); petrov_galerkin gives a
  // non-symmetric tangent, which every backend of linear_solver.hpp (LU) handles.
  ResidualForm residual_form = ResidualForm::consistent;
  int sample_points_per_element = 6;

  void finalize();  // builds the DOF map; required before solving

  // ---- queries ----
  int num_nodes() const { return static_cast<int>(X_.size()); }
  int num_elements() const { return static_cast<int>(elem_nodes_.size()); }
  int num_free_dofs() const { return nfree_; }
  const Vec3& reference_position(int n) const { return X_[n]; }
  const Vec3& position(int n) const { return x_[n]; }
  const std::vector<Vec3>& positions(bool reference = false) const { return reference ? X_ : x_; }
  const Quat& rotation(int n) const { return R_[n]; }
  std::array<int, 2> element_nodes(int e) const { return elem_nodes_[e]; }
  const ElementReference& element_reference(int e) const { return eref_[e]; }
  const Section& element_section(int e) const { return sections_[elem_section_[e]]; }
  const PlasticState& committed_state(int e) const { return mp_committed_[e]; }
  const PlasticState& trial_state(int e) const { return mp_trial_[e]; }
  double bending_moment_norm(int e) const { return mnorm_[e]; }
  Vec6 stress_resultants(int e) const { return stress_[e]; }
  Vec6 strain(int e) const;  // current convected strain (Γ, Ω)
  double time() const { return time_; }

  // Contact sample points (Gauss–Legendre points per element).
  int num_sample_points() const { return num_elements() * sample_points_per_element; }
  Vec3 sample_position(int g) const;
  double sample_weight(int g) const;
  double sample_radius(int g) const;
  void set_sample_line_loads(const std::vector<Vec3>& q);  // N/mm, one per sample point
  // Robin mode: K frozen contact planes per sample point (eps = 0: none; plane j of point g at
  // g·K + j, one per contact surface), see plane_penalty.hpp. Their penalty loads are added to the
  // sample line loads and linearized; empty: no planes.
  struct SamplePlane {
    Vec3 s = Vec3::Zero(), n = Vec3::Zero();
    double eps = 0.0;
    double g0 = 0.0;  // mm, regularization of the law (plane_penalty.hpp)
  };
  void set_sample_planes(std::vector<SamplePlane> planes);
  const std::vector<SamplePlane>& sample_planes() const { return planes_; }
  // Linearized response at the current state (the interface Newton–Krylov, docs/design.md §5.5):
  // the sample points' displacement when plane i moves by shift[i] along its normal and its normal
  // turns by turn[i] (empty: no turn), K du = −∂r/∂(shift, turn) with the tangent here (the planes'
  // penalty included). The state is left as it was. Throws std::invalid_argument if shift (or a
  // non-empty turn) is not one value per plane, std::runtime_error if the tangent cannot be factorized.
  std::vector<Vec3> plane_response(const std::vector<double>& shift, const std::vector<Vec3>& turn = {});
  // Sample line loads plus the planes' penalty loads at the current configuration (N/mm).
  std::vector<Vec3> sample_contact_loads() const;
  const std::vector<Vec3>& sample_line_loads() const { return q_ext_; }
  // Nodal forces consistent with sample_contact_loads() (for output), N per node.
  std::vector<Vec3> sample_load_nodal_forces() const;

  // Mean radial distance of all nodes from the (reference) device axis, times 2, at the current or
  // the reference positions (mean_diameter, ring_axis.hpp; generated stents are measured about
  // their deformed axis instead).
  double diameter(bool reference = false) const;

  // ---- state ----
  void set_time(double t);  // evaluates load curves and applies prescribed values
  NewtonStats solve();
  void commit();
  void restore();
  // Direct manipulation (tests): rigid motion of the current state.
  void set_state(const std::vector<Vec3>& x, const std::vector<Quat>& R);
  // Continue from a committed state (state_file.hpp): positions, rotations and the plastic state of
  // every element become the committed and current ones at time t.
  void start_from(double t, const std::vector<Vec3>& x, const std::vector<Quat>& R,
                  const std::vector<PlasticState>& plastic);

  // Internal residual/tangent in the reduced (free) DOFs at the current state.
  void assemble(SpMat* K, Eigen::VectorXd& r);
  // Full 6N residual (internal − external) in the global basis, for reactions and tests.
  Eigen::VectorXd global_residual();

  // x ← x + α Δx, R ← exp(α Δθ) R for an increment of the free DOFs.
  void apply_increment(const Eigen::VectorXd& d, double alpha = 1.0);

 private:
  void fix_cylindrical(int node, bool circumferential, bool axial);
  // Element evaluation and assembly into the full 6N residual rg (global basis) and, with K, the
  // reduced tangent; assemble() and global_residual() reduce / return rg.
  void assemble_global(SpMat* K, Eigen::VectorXd& rg);

  std::vector<Vec3> X_;
  std::vector<std::array<int, 2>> elem_nodes_;
  std::vector<int> elem_section_;
  std::vector<ElementReference> eref_;
  std::vector<Section> sections_;
  std::vector<Mat3> basis_;
  std::vector<std::array<bool, 6>> fixed_;
  std::vector<std::array<int, 6>> free_;
  int nfree_ = -1;

  std::vector<Vec3> x_, xc_;
  std::vector<Quat> R_, Rc_;
  std::vector<PlasticState> mp_committed_, mp_trial_;
  std::vector<double> mnorm_;
  std::vector<Vec6> stress_;
  std::vector<Vec3> q_ext_;
  std::vector<SamplePlane> planes_;
  int planes_per_point_ = 0;
  std::vector<Vec3> ref_radial_;  // reference radial direction per sample point
  std::vector<char> identity_basis_;
  std::vector<int> elem_dofs_;  // per element its 12 free DOF indices (−1: fixed)
  SpMat pattern_;               // sparsity pattern of the reduced tangent (built once)
  std::vector<int> elem_pos_;   // per element 144 positions into pattern_ values (−1: fixed)
  // assembly scratch, reused between calls: element results and per-element distributed loads
  std::vector<ElementResult> elem_results_;
  std::vector<Vec3> elem_q_;                           // uniform line load (N/mm)
  std::vector<double> elem_p_follower_, elem_p_dead_;  // radial line loads (N/mm)
  std::vector<double> gauss_xi_, gauss_w_;
  double time_ = 0;
  std::unique_ptr<LinearSolver> lin_;
  // plane_response()'s tangent, factorized once per state: the state, planes and loads it was made
  // at (compared on every call: a solve, a commit or new planes make it stale) and the residual there
  struct ResponseTangent {
    std::vector<Vec3> x, q;
    std::vector<Quat> R;
    std::vector<SamplePlane> planes;
    double time = 0.0;
    Eigen::VectorXd r;
    SpMat K;  // factorized in lin, which may read it again in its solves (UMFPACK does)
    std::unique_ptr<LinearSolver> lin;
    bool matches(const BeamModel& m) const;
  };
  ResponseTangent response_;
};

// Gauss–Legendre points on [0, 1] and weights summing to 1 (n = 1..6).
void gauss_legendre_01(int n, std::vector<double>& xi, std::vector<double>& w);

}  // namespace angio::beam
