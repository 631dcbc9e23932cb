#include "angio/contact/surface_contact.hpp"

#include <cmath>

#include "angio/participant/penalty_law.hpp"

namespace angio::contact {

double surface_gp_kernel(FaceKind sk, const FaceX& Xs, const Vec2& xi_g, double w_g, FaceKind mk, const FaceX& Xm,
                         double master_sign, const Projection& proj, double eps, double g0, Eigen::VectorXd& r,
                         Eigen::MatrixXd* K) {
  const int ns = num_nodes(sk), nm = num_nodes(mk);
  const int ms = 3 * ns, mm = 3 * nm, m = ms + mm;
  r.setZero(m);
  if (K) K->setZero(m, m);
  const double g = proj.d;
  if (!(g < std::max(g0, 0.0))) return g;
  // potential per area pi(g), pressure f = -pi'(g), stiffness k = pi''(g)
  const participant::PenaltyLaw law = participant::penalty_law(g, g0, eps);

  ShapeN Ns;
  ShapeD dNs;
  shape(sk, xi_g, Ns, &dNs);
  const Vec3 x = Xs * Ns;
  const Vec3 a1 = Xs * dNs.col(0), a2 = Xs * dNs.col(1);
  const Vec3 nt = a1.cross(a2);
  const double j = nt.norm();
  const Vec3 nu = nt / j;
  const double W = w_g * j;

  GapLinearization L;
  linearize(mk, Xm, master_sign, x, proj, K != nullptr, L);

  // dg/du: slave block a = N_a dd_x, master block = dd_X
  Eigen::RowVectorXd dg(m);
  for (int a = 0; a < ns; ++a) dg.segment<3>(3 * a) = Ns(a) * L.dd.segment<3>(0);
  dg.segment(ms, mm) = L.dd.segment(3, mm);
  // dW/du (slave block only): dj/dX_a = -N_a,1 (nu x a2) + N_a,2 (nu x a1)
  Eigen::RowVectorXd dW = Eigen::RowVectorXd::Zero(m);
  Eigen::MatrixXd Dn(3, ms);  // d(a1 x a2)/dX_s
  for (int a = 0; a < ns; ++a) {
    dW.segment<3>(3 * a) = w_g * (-dNs(a, 0) * nu.cross(a2) + dNs(a, 1) * nu.cross(a1)).transpose();
    Dn.block<3, 3>(0, 3 * a) = d_area_vector(dNs(a, 0), dNs(a, 1), a1, a2);
  }
  // Pi = W pi(g): r = pi dW + W pi' dg
  r = law.pi * dW.transpose() - (W * law.f) * dg.transpose();
  if (!K) return g;

  // d2g/du2 from the x-X Hessian of d with x = sum_a N_a X^s_a
  const Eigen::MatrixXd& h = L.hd;  // (3 + mm)^2, u' = [x, X_m]
  Eigen::MatrixXd d2g = Eigen::MatrixXd::Zero(m, m);
  for (int a = 0; a < ns; ++a) {
    for (int b = 0; b < ns; ++b) d2g.block<3, 3>(3 * a, 3 * b) = Ns(a) * Ns(b) * h.topLeftCorner<3, 3>();
    d2g.block(3 * a, ms, 3, mm) = Ns(a) * h.topRightCorner(3, mm);
    d2g.block(ms, 3 * a, mm, 3) = Ns(a) * h.bottomLeftCorner(mm, 3);
  }
  d2g.bottomRightCorner(mm, mm) = h.bottomRightCorner(mm, mm);
  // d2W (slave block): w_g [Dn^T (I - nu nu) Dn / j + (N_a,2 N_b,1 - N_a,1 N_b,2) [nu]x]
  Eigen::MatrixXd d2W = Eigen::MatrixXd::Zero(m, m);
  const Mat3 T = Mat3::Identity() - nu * nu.transpose();
  d2W.topLeftCorner(ms, ms) = Dn.transpose() * T * Dn / j;
  const Mat3 S = skew(nu);
  for (int a = 0; a < ns; ++a)
    for (int b = 0; b < ns; ++b) d2W.block<3, 3>(3 * a, 3 * b) += (dNs(a, 1) * dNs(b, 0) - dNs(a, 0) * dNs(b, 1)) * S;
  d2W *= w_g;

  // K = pi d2W + pi' (dW^T dg + dg^T dW) + W (pi'' dg^T dg + pi' d2g)
  *K = law.pi * d2W - law.f * (dW.transpose() * dg + dg.transpose() * dW) +
       W * (law.k * (dg.transpose() * dg) - law.f * d2g);
  return g;
}

namespace {
void one_pass(int pass, const SurfaceSearch& slave, const SurfaceSearch& master, double eps,
              const SurfaceContactParams& par, SurfaceContactResult& res) {
  const Surface& ss = slave.surface();
  const Surface& ms = master.surface();
  for (std::size_t fs = 0; fs < ss.faces.size(); ++fs) {
    const Face& sf = ss.faces[fs];
    const FaceX& Xs = slave.face_coords(static_cast<int>(fs));
    const QuadratureRule rule = face_rule(sf.kind, par.quadrature_degree);
    for (std::size_t q = 0; q < rule.xi.size(); ++q) {
      ShapeN N;
      ShapeD dN;
      shape(sf.kind, rule.xi[q], N, &dN);
      const Vec3 x = Xs * N;
      const double W = rule.w[q] * (Xs * dN.col(0)).cross(Xs * dN.col(1)).norm();
      const SurfaceProjection sp = master.closest(x, par.projection);
      if (!sp.found) continue;
      const Face& mf = ms.faces[sp.face];
      GaussPointContact gp;
      gp.pass = pass;
      gp.slave_face = static_cast<int>(fs);
      gp.master_face = sp.face;
      gp.gauss_point = static_cast<int>(q);
      gp.x = x;
      gp.s = sp.proj.s;
      gp.n = sp.proj.n;
      gp.gap = sp.proj.d;
      gp.area = W;
      gp.location = sp.proj.location;
      gp.active = gp.gap < par.regularization;
      const participant::PenaltyLaw law = participant::penalty_law(gp.gap, par.regularization, eps);
      gp.pressure = gp.active ? law.f : 0.0;
      ++res.diag.num_points;
      res.diag.min_gap = std::min(res.diag.min_gap, gp.gap);
      if (gp.active) {
        ++res.diag.num_active;
        NodalContribution nc;
        surface_gp_kernel(sf.kind, Xs, rule.xi[q], rule.w[q], mf.kind, master.face_coords(sp.face), ms.normal_sign,
                          sp.proj, eps, par.regularization, nc.r, par.compute_tangent ? &nc.K : nullptr);
        nc.nodes.assign(sf.nodes.begin(), sf.nodes.begin() + sf.nn());
        nc.nodes.insert(nc.nodes.end(), mf.nodes.begin(), mf.nodes.begin() + mf.nn());
        nc.surface = pass;
        nc.point = static_cast<int>(res.points.size());
        const Vec3 f_master = gp.pressure * W * (-gp.n);  // force on the master side of this pair
        res.diag.force_on_solid += pass == 0 ? f_master : Vec3(-f_master);
        res.diag.force_magnitude += gp.pressure * W;
        res.diag.energy += W * law.pi;
        res.active_area += W;
        res.contributions.push_back(std::move(nc));
      }
      res.points.push_back(gp);
    }
  }
}
}  // namespace

SurfaceContactResult evaluate_surface_contact(const SurfaceSearch& slave, const SurfaceSearch& master,
                                              const SurfaceContactParams& par) {
  SurfaceContactResult res;
  const double eps = par.two_pass ? 0.5 * par.penalty : par.penalty;
  one_pass(0, slave, master, eps, par, res);
  if (par.two_pass) one_pass(1, master, slave, eps, par, res);
  return res;
}

}  // namespace angio::contact
