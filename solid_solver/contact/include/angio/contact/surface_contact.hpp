// Surface-to-surface frictionless penalty contact (balloon outer surface -> artery endothelium),
// Gauss-point-to-segment: Gauss points on the slave faces, closest-point projection onto the master.
//
// Per slave Gauss point x = sum_a N_a(xi_g) X^s_a with weight W = w_g j(xi_g) (CURRENT area, j = |x_,xi x x_,eta|):
//   s, n = closest point on the master surface and its contact normal (toward the slave)
//   g_N  = (x - s) . n,    Pi = W eps/2 <g_N>^2,    traction on the slave t = -eps <g_N> n (pressure p = -eps <g_N>)
//   or, with a regularization g0 > 0, Pi = W pi(g_N) with the C1 linear-quadratic law of the line contact
//   (participant/penalty_law.hpp: pressure zero at g_N = g0, quadratic up to 0, linear beyond), so that a
//   Gauss point entering or leaving contact changes the force and the tangent continuously
//   r    = dPi/du, K = d2Pi/du2 with u = [slave face nodes, master face nodes]
// (includes the variation of the current area, of the closest point and of the master normal).
// Forces on the nodes are -r; slave and master forces balance exactly.
#pragma once
#include <vector>

#include "angio/contact/line_contact.hpp"

namespace angio::contact {

struct SurfaceContactParams {
  // the defaults of the scene's contact.balloon_artery (core/scene/keys.yaml)
  // eps: pressure per penetration (MPa/mm = N/mm^3); the paper writes 5 N/mm^2, see solid_solver/contact/README.md
  double penalty = scene::keys::defaults::contact_balloon_artery_penalty;
  // slave quadrature degree (face_rule): 3 = quad 2x2, tri 6 points
  int quadrature_degree = scene::keys::defaults::contact_balloon_artery_quadrature;
  // g0 (mm): C1 law, active where g_N < g0; 0: the paper's quadratic potential
  double regularization = scene::keys::defaults::contact_balloon_artery_regularization;
  // symmetric: both surfaces act as slave, each pass with eps/2
  bool two_pass = scene::keys::defaults::contact_balloon_artery_two_pass;
  bool compute_tangent = true;
  ProjectionOptions projection;
};

struct GaussPointContact {
  int pass = 0;  // 0: slave->master, 1: master->slave (two_pass)
  int slave_face = -1, master_face = -1;
  int gauss_point = -1;   // index in the slave face rule
  Vec3 x = Vec3::Zero();  // Gauss point
  Vec3 s = Vec3::Zero();  // closest point on the master
  Vec3 n = Vec3::Zero();  // master contact normal
  double gap = 0.0;       // g_N
  double pressure = 0.0;  // contact pressure (MPa): -eps <g_N>, or the regularized law's
  double area = 0.0;      // W = w_g j (mm^2)
  bool active = false;
  Location location = Location::Interior;
};

struct SurfaceContactResult {
  std::vector<NodalContribution> contributions;  // active Gauss points; nodes = slave face nodes then master face nodes
  std::vector<GaussPointContact> points;         // every slave Gauss point with a master point in the search radius
  ContactDiagnostics diag;                       // force_on_solid = net force on the master surface (pass 0)
  double active_area = 0.0;                      // sum of W over active Gauss points
};

// Pure kernel for one slave Gauss point whose master projection is known.
// r (3(ns+nm)) and K (if non-null) are overwritten; returns g_N. g0: the regularization (0: none).
double surface_gp_kernel(FaceKind slave_kind, const FaceX& Xs, const Vec2& xi_g, double w_g, FaceKind master_kind,
                         const FaceX& Xm, double master_sign, const Projection& proj, double penalty, double g0,
                         Eigen::VectorXd& r, Eigen::MatrixXd* K);

// Evaluate contact of `slave` against `master` (both searches update()d with the current coordinates;
// the master's radius is the search radius; the slave's search is used only as master in pass 1).
SurfaceContactResult evaluate_surface_contact(const SurfaceSearch& slave, const SurfaceSearch& master,
                                              const SurfaceContactParams& par);

}  // namespace angio::contact
