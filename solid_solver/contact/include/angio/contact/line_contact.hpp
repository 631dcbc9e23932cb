// Line-to-surface penalty contact: beam (stent) sample points against solid surfaces (docs/design.md §8).
//
// Per beam sample point x (weight w = arc length, mm; beam contact radius R) and surface:
//   s, n   closest point on the surface and unit contact normal toward the beam
//   g    = (x - s) . n - R,   <g> = min(g, 0),   Pi = w eps/2 <g>^2
//   q    = -eps <g> n                    line load on the BEAM (N/mm), pushes the beam away from the surface
//   f_a  = -w q N_a(xi)                  force on solid face node a (N), equal and opposite
// Solid assembly (r = f_int - f_ext convention of angio::solid): r_a += dPi/dX_a = -f_a,
//   K_ab += d2Pi/dX_a dX_b  (beam point x held fixed; includes the variation of the closest point and of n).
#pragma once
#include <vector>

#include "angio/contact/search.hpp"
#include "angio/scene/keys_generated.hpp"

namespace angio::contact {

struct BeamPoint {
  Vec3 x = Vec3::Zero();  // position (mm)
  double w = 0.0;         // integration weight along the centreline (mm)
  double R = 0.0;         // beam contact radius (mm)
};

// The paper's line-contact penalty for stent–balloon and stent–artery (§2.5: ε = 10 N/mm², a line
// load per mm of penetration), the default of every line-contact pair.
inline constexpr double kLinePenaltyDefault = scene::keys::defaults::contact_stent_balloon_penalty;
static_assert(scene::keys::defaults::contact_stent_balloon_penalty ==
              scene::keys::defaults::contact_stent_artery_penalty);

struct LineContactParams {
  double penalty = kLinePenaltyDefault;  // eps (N/mm^2)
  // g0 (mm): 0 = the paper's linear penalty law q = −eps⟨g⟩ (Eq. 4); g0 > 0 = the C¹
  // "linear-quadratic" law of 4C's beam-to-solid contact: q = eps (g0/2 − g) for g ≤ 0,
  // eps (g0 − g)²/(2 g0) for 0 < g < g0, 0 beyond. It removes the jump of the stiffness at
  // g = 0 that makes Newton cycle when many points sit at the kink (shift of the contact
  // surface: g0/2 at most).
  double regularization = 0.0;
  // false: s, n from the closest-point projection (projection.hpp); the normal jumps where the
  // closest face changes over a concave kink. true: s, n from the projection along the averaged
  // nodal normal field (normal_field.hpp), continuous over the surface; then
  //   q = f(g) nu, f_a = -w q N_a(xi), g = d - R, and K is the tangent with the nodal normals held
  //   fixed (not symmetric).
  bool averaged_normals = false;
  // averaged normals only. true: K over the face's nodes and the other nodes of their rings (the
  // nodal normals' dependence on every node they average over). false: K over the face's own nodes
  // only (the columns of the other ring nodes left out, the face nodes' columns exact); the residual
  // is the same, so a Newton with this tangent converges to the same solution. The ring columns
  // widen the solid's matrix pattern to the surface's second neighbours, which makes its direct
  // factorization 2.5x dearer on a balloon one element thick (docs/performance.md).
  bool ring_tangent = true;
  // false: K leaves out the terms proportional to the force's magnitude f (f hd with the closest point;
  // with averaged normals f dnu, the normal's rotation, and f nu dN_a, the point's slide over the face)
  // and keeps the penalty's stiffness along the gap, k nu (x) dg/du. A strut pressed into a fine, soft lumen makes the
  // left-out terms large against the wall's own stiffness (about f/h against E h per node: the ratio grows as 1/h^2)
  // and the exact tangent indefinite there; Newton's steps then move lumen nodes by millimetres (docs/performance.md,
  // "The step where the 0.25 mm wall inverts"). Without them Newton converges linearly to the same solution (the
  // residual is the same). The scene's `contact.line_tangent: gap`.
  bool force_tangent = true;
  // With force_tangent: the force's terms K_f enter as the positive semidefinite part of their symmetric part,
  // K = K_gap + P+((K_f + K_f^T)/2) (eigenvalues below zero set to zero), over the face's own nodes (no ring
  // columns): the stiffening the force's terms give is kept, the indefiniteness a strut's load brings on a soft,
  // fine lumen (above) left out; the scene's `contact.line_tangent: definite`. (The projection of each contact
  // term's Hessian onto the definite cone: Teran et al. 2005, Li et al. 2020, "incremental potential contact".)
  bool definite_force_terms = false;
  bool compute_tangent = true;  // fill NodalContribution::K
  bool beam_tangent = false;    // fill PointContact::dq_dx
  ProjectionOptions projection;
};

// Nodal residual/tangent contribution of one contact point (or Gauss point) to the solid.
struct NodalContribution {
  std::vector<int> nodes;  // node ids (as in the faces), 3 dofs each, dof = 3*local + component
  // dPi/dX (= minus the contact forces) on the first r.size()/3 nodes; the nodes after them only enter the
  // tangent's columns (averaged normals: the ring around the face).
  Eigen::VectorXd r;
  Eigen::MatrixXd K;  // dr/dX (r.size() x 3 nodes; symmetric for the closest-point and surface contact),
                      // empty if no tangent requested
  int surface = -1;   // line contact: index of the surface; surface contact: pass (0, or 1 if two_pass)
  int point = -1;     // line contact: beam point index; surface contact: index into SurfaceContactResult::points
};

// One beam point against one surface.
struct PointContact {
  bool found = false;   // a face within the search radius
  bool active = false;  // g < 0
  int face = -1;
  Projection proj;            // s, n (toward the beam), xi, location
  double gap = 0.0;           // g = (x - s).n - R (only if found)
  Vec3 q = Vec3::Zero();      // line load on the beam (N/mm)
  double energy = 0.0;        // penalty potential w pi(g) of this pair (N mm)
  Mat3 dq_dx = Mat3::Zero();  // dq/dx with the surface fixed (if beam_tangent)
};

struct ContactDiagnostics {
  int num_points = 0;  // evaluated (point, surface) pairs with a closest point in range
  int num_active = 0;  // with g < 0
  double min_gap = std::numeric_limits<double>::infinity();  // smallest gap (most negative = largest penetration)
  Vec3 force_on_solid = Vec3::Zero();                        // sum of nodal forces on the solid (N)
  double force_magnitude = 0.0;                              // sum over points of |force| (N)
  double energy = 0.0;                                       // penalty potential Pi (N mm); r = dPi/dX
  void merge(const ContactDiagnostics& o);
};

struct LineContactResult {
  std::vector<Vec3> q;                                 // per point: line load on the beam summed over surfaces
  Vec3 force_on_beam = Vec3::Zero();                   // sum_i w_i q_i (N) = -diag.force_on_solid
  std::vector<std::vector<PointContact>> per_surface;  // [surface][point]
  std::vector<NodalContribution> solid;                // active (point, surface) pairs
  ContactDiagnostics diag;
};

// Robin-mode data per beam point (docs/design.md §5.3): the beam linearizes q(x) = -eps <(x - s).n - R> n.
// A point can see several surfaces; only one plane per point is representable, so the surface with the
// smallest gap g among those with a closest point in range is reported (the line loads q above stay the exact
// sum). found = false: no surface within the search radius (s, n zero).
struct RobinPoint {
  bool found = false;
  bool active = false;  // g < 0
  int surface = -1;
  Vec3 s = Vec3::Zero();
  Vec3 n = Vec3::Zero();  // unit normal toward the beam
  double gap = 0.0;
  double penalty = 0.0;  // eps
};
std::vector<RobinPoint> robin_points(const LineContactResult& res, double penalty);

// Evaluate one point against one face whose closest point is already known (pure kernel).
// Returns the contribution on the face nodes (r, K as documented above) and fills pc.gap, pc.q, pc.active.
void line_point_kernel(const BeamPoint& bp, FaceKind kind, const FaceX& X, double normal_sign, const Projection& proj,
                       const LineContactParams& par, PointContact& pc, Eigen::VectorXd& r, Eigen::MatrixXd* K);

// The same for a point projected along the averaged normal field (LineContactParams::averaged_normals);
// Nn: the face's nodal normals (SurfaceSearch::face_normals). K = dr/d[X_0..X_{nn-1}, n_0..n_{nn-1}]
// (3 nn x 6 nn); evaluate_line_contact chains the normal columns to the nodes around the face. Kf (optional,
// with K and par.force_tangent): the terms proportional to the force apart, over the same columns; K then holds
// the rest (the gap's stiffness), K + Kf the full tangent. Kf is written for an active point only.
void line_point_kernel_averaged(const BeamPoint& bp, FaceKind kind, const FaceX& X, const FaceX& Nn,
                                const NormalFieldProjection& proj, const LineContactParams& par, PointContact& pc,
                                Eigen::VectorXd& r, Eigen::MatrixXd* K, Eigen::MatrixXd* Kf = nullptr);

// Evaluate all points against all surfaces (searches must be update()d with the current coordinates).
// The contributions of different surfaces add up (a point may touch balloon and artery at the same time).
// hints (averaged normals; optional): per surface, one per point, where each point projected at the last
// evaluation (SurfaceSearch::along_normals); read as starts and overwritten with this evaluation's. An
// empty span for a surface: no hints there. Other shapes throw std::invalid_argument.
LineContactResult evaluate_line_contact(std::span<const BeamPoint> points,
                                        std::span<const SurfaceSearch* const> surfaces, const LineContactParams& par,
                                        std::span<const std::span<ProjectionHint>> hints = {});

}  // namespace angio::contact
