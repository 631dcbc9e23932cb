#include "angio/contact/line_contact.hpp"

#include <cmath>

namespace angio::contact {

void ContactDiagnostics::merge(const ContactDiagnostics& o) {
  num_points += o.num_points;
  num_active += o.num_active;
  min_gap = std::min(min_gap, o.min_gap);
  force_on_solid += o.force_on_solid;
  force_magnitude += o.force_magnitude;
  energy += o.energy;
}

namespace {
// Penalty law of LineContactParams at gap g: potential pi(g), force magnitude f = −dpi/dg and k = −df/dg
// (linear law for g0 = 0, the g0 → 0 limit of the linear-quadratic one).
struct PenaltyLaw {
  double pi, f, k;
};
PenaltyLaw penalty_law(double g, double g0, double eps) {
  if (g0 <= 0.0) return {0.5 * eps * g * g, -eps * g, eps};
  if (g <= 0.0) return {eps * (0.5 * g * g - 0.5 * g0 * g + g0 * g0 / 6.0), eps * (0.5 * g0 - g), eps};
  return {eps * (g0 - g) * (g0 - g) * (g0 - g) / (6.0 * g0), 0.5 * eps * (g0 - g) * (g0 - g) / g0, eps * (g0 - g) / g0};
}
}  // namespace

void line_point_kernel(const BeamPoint& bp, FaceKind kind, const FaceX& X, double normal_sign, const Projection& proj,
                       const LineContactParams& par, PointContact& pc, Eigen::VectorXd& r, Eigen::MatrixXd* K) {
  const int nn = num_nodes(kind);
  pc.proj = proj;
  pc.gap = proj.d - bp.R;
  const double g0 = par.regularization;
  pc.active = pc.gap < g0;
  pc.q.setZero();
  pc.dq_dx.setZero();
  pc.energy = 0.0;
  r.setZero(3 * nn);
  if (K) K->setZero(3 * nn, 3 * nn);
  if (!pc.active) return;
  const double w = bp.w;
  const auto [pi, f, k] = penalty_law(pc.gap, g0, par.penalty);
  pc.energy = w * pi;
  pc.q = f * proj.n;
  const bool need_h = K != nullptr || par.beam_tangent;
  GapLinearization L;
  linearize(kind, X, normal_sign, bp.x, proj, need_h, L);
  // Pi = w pi(g); dPi/du = −w f dd; d2Pi/du2 = w (k dd^T dd − f hd), u = [x, X]
  const int m = L.m;
  r = -w * f * L.dd.segment(3, m - 3).transpose();
  if (K) {
    const Eigen::RowVectorXd dX = L.dd.segment(3, m - 3);
    *K = w * (k * dX.transpose() * dX - f * L.hd.bottomRightCorner(m - 3, m - 3));
  }
  if (par.beam_tangent) {
    // q = f n: dq/dx = −k n dd_x + f dn_x
    pc.dq_dx = -k * proj.n * L.dd.segment<3>(0) + f * L.dn.leftCols<3>();
  }
}

LineContactResult evaluate_line_contact(std::span<const BeamPoint> points, std::span<const SurfaceSearch* const> surfaces,
                                        const LineContactParams& par) {
  LineContactResult res;
  res.q.assign(points.size(), Vec3::Zero());
  res.per_surface.resize(surfaces.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const SurfaceSearch& S = *surfaces[k];
    const Surface& surf = S.surface();
    auto& pcs = res.per_surface[k];
    pcs.assign(points.size(), PointContact{});
    for (std::size_t i = 0; i < points.size(); ++i) {
      const BeamPoint& bp = points[i];
      const SurfaceProjection sp = S.closest(bp.x, par.projection);
      PointContact& pc = pcs[i];
      if (!sp.found) continue;
      pc.found = true;
      pc.face = sp.face;
      const Face& face = surf.faces[sp.face];
      NodalContribution nc;
      line_point_kernel(bp, face.kind, S.face_coords(sp.face), surf.normal_sign, sp.proj, par, pc, nc.r,
                        par.compute_tangent ? &nc.K : nullptr);
      ++res.diag.num_points;
      res.diag.min_gap = std::min(res.diag.min_gap, pc.gap);
      if (!pc.active) continue;
      ++res.diag.num_active;
      res.q[i] += pc.q;
      res.force_on_beam += bp.w * pc.q;
      res.diag.force_on_solid -= bp.w * pc.q;
      res.diag.force_magnitude += bp.w * pc.q.norm();
      res.diag.energy += pc.energy;
      nc.nodes.assign(face.nodes.begin(), face.nodes.begin() + face.nn());
      nc.surface = static_cast<int>(k);
      nc.point = static_cast<int>(i);
      res.solid.push_back(std::move(nc));
    }
  }
  return res;
}

std::vector<RobinPoint> robin_points(const LineContactResult& res, double penalty) {
  std::vector<RobinPoint> out(res.q.size());
  for (std::size_t k = 0; k < res.per_surface.size(); ++k)
    for (std::size_t i = 0; i < out.size() && i < res.per_surface[k].size(); ++i) {
      const PointContact& pc = res.per_surface[k][i];
      if (!pc.found || (out[i].found && pc.gap >= out[i].gap)) continue;
      RobinPoint& rp = out[i];
      rp.found = true;
      rp.active = pc.active;
      rp.surface = static_cast<int>(k);
      rp.s = pc.proj.s;
      rp.n = pc.proj.n;
      rp.gap = pc.gap;
      rp.penalty = penalty;
    }
  return out;
}

}  // namespace angio::contact
