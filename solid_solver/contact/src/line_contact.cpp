#include "angio/contact/line_contact.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "angio/participant/penalty_law.hpp"

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
using participant::penalty_law;  // the one law of the stent's line contact, shared with the robin planes
using participant::PenaltyLaw;

// Common start of both point kernels: the gap g = d − R, activity g < g0, everything reset (r: 3 nn,
// K: 3 nn x k_cols). Returns the penalty law at g if the point is active.
std::optional<PenaltyLaw> start_point(const BeamPoint& bp, double d, int nn, int k_cols, const LineContactParams& par,
                                      PointContact& pc, Eigen::VectorXd& r, Eigen::MatrixXd* K) {
  pc.gap = d - bp.R;
  pc.active = pc.gap < par.regularization;
  pc.q.setZero();
  pc.dq_dx.setZero();
  pc.energy = 0.0;
  r.setZero(3 * nn);
  if (K) K->setZero(3 * nn, k_cols);
  if (!pc.active) return std::nullopt;
  const PenaltyLaw law = penalty_law(pc.gap, par.regularization, par.penalty);
  pc.energy = bp.w * law.pi;
  return law;
}

// A += P+((B + B^T)/2), A and B square over the face's nodes: the positive semidefinite part of B's symmetric
// part (LineContactParams::definite_force_terms), in fixed-capacity storage. An eigensolver that fails (a
// non-finite B) adds nothing: the point keeps the gap's stiffness alone.
using FaceSquare =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 3 * kMaxFaceNodes, 3 * kMaxFaceNodes>;
void add_definite_part(const Eigen::Ref<const Eigen::MatrixXd>& B, Eigen::Ref<Eigen::MatrixXd> A) {
  if (B.rows() != B.cols() || B.rows() > 3 * kMaxFaceNodes || A.rows() != B.rows() || A.cols() != B.cols())
    throw std::logic_error("line contact: the definite tangent needs square terms over one face's nodes");
  const FaceSquare S = 0.5 * (B + B.transpose());
  const Eigen::SelfAdjointEigenSolver<FaceSquare> eig(S);
  if (eig.info() != Eigen::Success) return;
  const auto& lambda = eig.eigenvalues();
  const auto& V = eig.eigenvectors();
  for (Eigen::Index j = 0; j < lambda.size(); ++j)
    if (lambda(j) > 0.0) A.noalias() += lambda(j) * V.col(j) * V.col(j).transpose();
}
}  // namespace

void line_point_kernel(const BeamPoint& bp, FaceKind kind, const FaceX& X, double normal_sign, const Projection& proj,
                       const LineContactParams& par, PointContact& pc, Eigen::VectorXd& r, Eigen::MatrixXd* K) {
  const int nn = num_nodes(kind);
  pc.proj = proj;
  const auto law = start_point(bp, proj.d, nn, 3 * nn, par, pc, r, K);
  if (!law) return;
  const auto [pi, f, k] = *law;
  const double w = bp.w;
  pc.q = f * proj.n;
  const bool need_h = K != nullptr || par.beam_tangent;
  GapLinearization L;
  linearize(kind, X, normal_sign, bp.x, proj, need_h, L);
  // Pi = w pi(g); dPi/du = −w f dd; d2Pi/du2 = w (k dd^T dd − f hd), u = [x, X]
  const int m = L.m;
  r = -w * f * L.dd.segment(3, m - 3).transpose();
  if (K) {
    const Eigen::RowVectorXd dX = L.dd.segment(3, m - 3);
    *K = w * k * dX.transpose() * dX;
    if (par.force_tangent && par.definite_force_terms) {
      const FaceSquare Kf = -w * f * L.hd.bottomRightCorner(m - 3, m - 3);  // symmetric: the Hessian of d
      add_definite_part(Kf, *K);
    } else if (par.force_tangent) {
      *K -= w * f * L.hd.bottomRightCorner(m - 3, m - 3);
    }
  }
  if (par.beam_tangent) {
    // q = f n: dq/dx = −k n dd_x + f dn_x
    pc.dq_dx = -k * proj.n * L.dd.segment<3>(0) + f * L.dn.leftCols<3>();
  }
}

void line_point_kernel_averaged(const BeamPoint& bp, FaceKind kind, const FaceX& X, const FaceX& Nn,
                                const NormalFieldProjection& proj, const LineContactParams& par, PointContact& pc,
                                Eigen::VectorXd& r, Eigen::MatrixXd* K, Eigen::MatrixXd* Kf) {
  const int nn = num_nodes(kind);
  pc.proj = Projection{};
  pc.proj.valid = proj.valid;
  pc.proj.xi = proj.xi;
  pc.proj.s = proj.s;
  pc.proj.n = pc.proj.n_face = proj.nu;
  pc.proj.d = proj.d;
  pc.proj.distance = std::abs(proj.d);
  pc.proj.iterations = proj.iterations;
  const auto law = start_point(bp, proj.d, nn, 6 * nn, par, pc, r, K);
  if (!law) return;
  const auto [pi, f, k] = *law;
  const double w = bp.w;
  pc.q = f * proj.nu;
  NormalFieldLinearization L;
  if (K || par.beam_tangent)
    linearize(kind, X, Nn, proj, L);
  else
    shape(kind, proj.xi, L.N);
  // r_a = w f nu N_a (= minus the force on face node a); f = f(g), df = −k dg
  for (int a = 0; a < nn; ++a) r.segment<3>(3 * a) = w * f * L.N[a] * proj.nu;
  if (K) {
    // d(f nu)/du, 3 x m; without the force's terms (force_tangent) only the gap's stiffness; with Kf the force's
    // terms (f dnu, the normal's rotation; f nu dN_a, the point's slide) go there
    const bool apart = Kf != nullptr && par.force_tangent;
    const double fk = par.force_tangent && !apart ? f : 0.0;
    const Eigen::MatrixXd dq = -k * proj.nu * L.dd + fk * L.dnu;
    if (apart) Kf->setZero(3 * nn, 6 * nn);
    for (int a = 0; a < nn; ++a) {
      const Eigen::RowVectorXd dNa = L.dN(a, 0) * L.dxi.row(0) + L.dN(a, 1) * L.dxi.row(1);
      K->middleRows<3>(3 * a) = w * (L.N[a] * dq + fk * proj.nu * dNa).rightCols(6 * nn);
      if (apart) Kf->middleRows<3>(3 * a) = w * f * (L.N[a] * L.dnu + proj.nu * dNa).rightCols(6 * nn);
    }
  }
  if (par.beam_tangent) pc.dq_dx = -k * proj.nu * L.dd.head<3>() + f * L.dnu.leftCols<3>();
}

namespace {
// Turns the averaged kernel's tangent over [face nodes | face nodal normals] into one over the face nodes
// followed by the other nodes of their rings: K_ring += K_n,b dn_b/dX_ring (NodeNormal::dn). The residual
// stays on the face nodes (NodalContribution: rows = the first r.size()/3 nodes). Without `ring`, the
// columns of ring nodes outside the face are left out (LineContactParams::ring_tangent).
void chain_normals(const Face& face, const SurfaceSearch& S, bool ring, NodalContribution& nc) {
  const int nn = face.nn();
  nc.nodes.assign(face.nodes.begin(), face.nodes.begin() + nn);
  // column of node id; -1: a ring node outside the face, left out
  auto index = [&](int id) {
    const auto it = std::find(nc.nodes.begin(), nc.nodes.end(), id);
    if (it != nc.nodes.end()) return int(it - nc.nodes.begin());
    if (!ring) return -1;
    nc.nodes.push_back(id);
    return int(nc.nodes.size()) - 1;
  };
  for (int b = 0; b < nn; ++b)
    for (int id : S.node_normal(face.nodes[b]).ring) index(id);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * nn, 3 * Eigen::Index(nc.nodes.size()));
  K.leftCols(3 * nn) = nc.K.leftCols(3 * nn);
  for (int b = 0; b < nn; ++b) {
    const NodeNormal& nb = S.node_normal(face.nodes[b]);
    const auto Kn = nc.K.middleCols<3>(3 * nn + 3 * b);
    for (std::size_t j = 0; j < nb.ring.size(); ++j)
      if (const int col = index(nb.ring[j]); col >= 0) K.middleCols<3>(3 * col) += Kn * nb.dn.middleCols<3>(3 * j);
  }
  nc.K = std::move(K);
}
}  // namespace

LineContactResult evaluate_line_contact(std::span<const BeamPoint> points,
                                        std::span<const SurfaceSearch* const> surfaces, const LineContactParams& par,
                                        std::span<const std::span<ProjectionHint>> hints) {
  // hints of the wrong shape would be ignored silently (and the search pay its full price)
  if (!hints.empty() && hints.size() != surfaces.size())
    throw std::invalid_argument("evaluate_line_contact: hints need one span per surface");
  for (const auto& h : hints)
    if (!h.empty() && h.size() != points.size())
      throw std::invalid_argument("evaluate_line_contact: hints need one per point (or none for a surface)");
  LineContactResult res;
  res.q.assign(points.size(), Vec3::Zero());
  res.per_surface.resize(surfaces.size());
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const SurfaceSearch& S = *surfaces[k];
    const Surface& surf = S.surface();
    if (par.averaged_normals && par.compute_tangent && !S.normal_derivatives())
      throw std::logic_error(
          "evaluate_line_contact: a tangent along the normal field needs SurfaceSearch::update() "
          "with the normals' derivatives");
    auto& pcs = res.per_surface[k];
    const std::span<ProjectionHint> hint = hints.empty() ? std::span<ProjectionHint>{} : hints[k];
    pcs.assign(points.size(), PointContact{});
    NodalContribution nc;  // reused: its buffers are allocated again only after an active point took them
    // definite_force_terms with averaged normals: the force's terms apart, over the same columns
    const bool definite = par.averaged_normals && par.compute_tangent && par.force_tangent && par.definite_force_terms;
    NodalContribution force_nc;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const BeamPoint& bp = points[i];
      PointContact& pc = pcs[i];
      nc.nodes.clear();
      Eigen::MatrixXd* K = par.compute_tangent ? &nc.K : nullptr;
      if (par.averaged_normals) {
        ProjectionHint* h = hint.empty() ? nullptr : &hint[i];
        const SurfaceNormalProjection sp = S.along_normals(bp.x, par.projection.inside_tol, h);
        if (h) *h = sp.found ? ProjectionHint{sp.face, sp.proj.xi} : ProjectionHint{};
        if (!sp.found) continue;
        pc.face = sp.face;
        line_point_kernel_averaged(bp, surf.faces[sp.face].kind, S.face_coords(sp.face), S.face_normals(sp.face),
                                   sp.proj, par, pc, nc.r, K, definite ? &force_nc.K : nullptr);
        if (pc.active && K) chain_normals(surf.faces[sp.face], S, par.ring_tangent && !definite, nc);
        if (pc.active && definite) {  // K = K_gap + P+(sym K_f), over the face's nodes
          chain_normals(surf.faces[sp.face], S, false, force_nc);
          add_definite_part(force_nc.K, nc.K);
        }
      } else {
        const SurfaceProjection sp = S.closest(bp.x, par.projection);
        if (!sp.found) continue;
        pc.face = sp.face;
        line_point_kernel(bp, surf.faces[sp.face].kind, S.face_coords(sp.face), surf.normal_sign, sp.proj, par, pc,
                          nc.r, K);
      }
      pc.found = true;
      const Face& face = surf.faces[pc.face];
      ++res.diag.num_points;
      res.diag.min_gap = std::min(res.diag.min_gap, pc.gap);
      if (!pc.active) continue;
      ++res.diag.num_active;
      res.q[i] += pc.q;
      res.force_on_beam += bp.w * pc.q;
      res.diag.force_on_solid -= bp.w * pc.q;
      res.diag.force_magnitude += bp.w * pc.q.norm();
      res.diag.energy += pc.energy;
      if (nc.nodes.empty()) nc.nodes.assign(face.nodes.begin(), face.nodes.begin() + face.nn());
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
