#include "angio/contact/normal_field.hpp"

#include <algorithm>
#include <cmath>

namespace angio::contact {

namespace {
// Parameter coordinates of face node a (corners, then mid-edge nodes of tri6).
Vec2 node_xi(FaceKind k, int a) {
  const int nc = num_corners(k);
  if (a < nc) return corner_xi(k, a);
  const int e = a - nc;
  return 0.5 * (corner_xi(k, e) + corner_xi(k, (e + 1) % nc));
}
}  // namespace

std::vector<std::vector<int>> node_rings(const Surface& s, std::size_t num_nodes) {
  std::vector<std::vector<int>> rings(num_nodes);
  for (const Face& face : s.faces)
    for (int a = 0; a < face.nn(); ++a) {
      std::vector<int>& ring = rings[face.nodes[a]];
      for (int b = 0; b < face.nn(); ++b)
        if (std::find(ring.begin(), ring.end(), face.nodes[b]) == ring.end()) ring.push_back(face.nodes[b]);
    }
  return rings;
}

void nodal_normals(const Surface& s, std::span<const FaceX> X, std::size_t num_nodes, NodalNormals& out,
                   bool derivatives) {
  // v_a = sum over faces f at a of t_f(a) = c / |c|, c = x_,xi x x_,eta of f at a (times normal_sign);
  // dc/dX_b = d_area_vector (face.hpp), dt = (I - t t^T) dc / |c|, n_a = v_a / |v_a|.
  if (out.node.size() != num_nodes || out.face.size() != s.faces.size()) {
    out.node.assign(num_nodes, NodeNormal{});
    std::vector<std::vector<int>> rings = node_rings(s, num_nodes);
    for (std::size_t i = 0; i < num_nodes; ++i) out.node[i].ring = std::move(rings[i]);
    out.face.assign(s.faces.size(), FaceX());
    for (std::size_t f = 0; f < s.faces.size(); ++f) out.face[f].resize(3, s.faces[f].nn());
  }
  out.derivatives = derivatives;
  for (NodeNormal& nn : out.node) {
    nn.n.setZero();  // accumulates v_a first
    if (derivatives) nn.dn.setZero(3, 3 * Eigen::Index(nn.ring.size()));
  }
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    const Face& face = s.faces[f];
    for (int a = 0; a < face.nn(); ++a) {
      ShapeN N;
      ShapeD dN;
      shape(face.kind, node_xi(face.kind, a), N, &dN);
      const Vec3 a1 = X[f] * dN.col(0), a2 = X[f] * dN.col(1);
      const Vec3 c = s.normal_sign * a1.cross(a2);
      const double cn = c.norm();
      const Vec3 t = c / cn;
      NodeNormal& nn = out.node[face.nodes[a]];
      nn.n += t;
      if (!derivatives) continue;
      const Mat3 P = (Mat3::Identity() - t * t.transpose()) / cn;
      for (int b = 0; b < face.nn(); ++b) {
        const auto col = std::find(nn.ring.begin(), nn.ring.end(), face.nodes[b]) - nn.ring.begin();
        nn.dn.middleCols<3>(3 * col) += s.normal_sign * P * d_area_vector(dN(b, 0), dN(b, 1), a1, a2);
      }
    }
  }
  for (NodeNormal& nn : out.node) {
    if (nn.ring.empty()) continue;
    const double vn = nn.n.norm();
    nn.n /= vn;
    if (!derivatives) continue;
    const Mat3 P = (Mat3::Identity() - nn.n * nn.n.transpose()) / vn;
    for (Eigen::Index j = 0; j < nn.dn.cols(); j += 3) nn.dn.middleCols<3>(j) = (P * nn.dn.middleCols<3>(j)).eval();
  }
  for (std::size_t f = 0; f < s.faces.size(); ++f)
    for (int a = 0; a < s.faces[f].nn(); ++a) out.face[f].col(a) = out.node[s.faces[f].nodes[a]].n;
}

NormalFieldProjection project_along_normals(FaceKind k, const FaceX& X, const FaceX& Nn, const Vec3& x,
                                            double inside_tol, const Vec2* start, int max_iter) {
  NormalFieldProjection p;
  Vec2 xi = start ? *start : center_xi(k);
  ShapeN N;
  ShapeD dN;
  shape(k, xi, N, &dN);
  Vec3 m = Nn * N;
  double alpha = (x - X * N).dot(m) / m.squaredNorm();
  for (int it = 0; it < max_iter; ++it) {
    shape(k, xi, N, &dN);
    m = Nn * N;
    const Vec3 F = X * N + alpha * m - x;
    Mat3 J;
    J.col(0) = X * dN.col(0) + alpha * (Nn * dN.col(0));
    J.col(1) = X * dN.col(1) + alpha * (Nn * dN.col(1));
    J.col(2) = m;
    const Eigen::PartialPivLU<Mat3> lu(J);
    if (!(std::abs(lu.determinant()) > 1e-300)) return p;
    const Vec3 dy = -lu.solve(F);
    xi += dy.head<2>();
    alpha += dy[2];
    p.iterations = it + 1;
    if (!xi.allFinite() || xi.lpNorm<Eigen::Infinity>() > 10.0) return p;
    if (dy.head<2>().lpNorm<Eigen::Infinity>() < 1e-13 &&
        std::abs(dy[2]) * m.norm() < 1e-13 * (1.0 + std::abs(alpha))) {
      shape(k, xi, N, &dN);
      m = Nn * N;
      p.xi = xi;
      p.s = X * N;
      p.alpha = alpha;
      p.nu = m.normalized();
      p.d = alpha * m.norm();
      p.valid = inside(k, xi, inside_tol);
      return p;
    }
  }
  return p;
}

void linearize(FaceKind k, const FaceX& X, const FaceX& Nn, const NormalFieldProjection& p,
               NormalFieldLinearization& L) {
  const int nn = num_nodes(k);
  L.m = 3 + 6 * nn;
  shape(k, p.xi, L.N, &L.dN);
  const Vec3 m = Nn * L.N;
  const double mu = m.norm();
  const Vec3 m1 = Nn * L.dN.col(0), m2 = Nn * L.dN.col(1);
  Mat3 J;
  J.col(0) = X * L.dN.col(0) + p.alpha * m1;
  J.col(1) = X * L.dN.col(1) + p.alpha * m2;
  J.col(2) = m;
  const Mat3 Jinv = J.inverse();
  // F(y; u) = X N(xi) + alpha Nn N(xi) - x = 0, y = (xi, alpha):
  //   dy/dx = J^-1, dy/dX_b = -N_b J^-1, dy/dn_b = -alpha N_b J^-1
  Eigen::MatrixXd dy(3, L.m);
  dy.leftCols<3>() = Jinv;
  for (int b = 0; b < nn; ++b) {
    dy.middleCols<3>(3 + 3 * b) = -L.N[b] * Jinv;
    dy.middleCols<3>(3 + 3 * nn + 3 * b) = -p.alpha * L.N[b] * Jinv;
  }
  L.dxi = dy.topRows<2>();
  // m = sum_b N_b n_b: through xi, and directly through the nodal normals
  Eigen::MatrixXd dm = m1 * dy.row(0) + m2 * dy.row(1);
  for (int b = 0; b < nn; ++b) dm.middleCols<3>(3 + 3 * nn + 3 * b) += L.N[b] * Mat3::Identity();
  const Vec3 nu = m / mu;
  // d = alpha |m|, nu = m / |m|
  L.dd = mu * dy.row(2) + p.alpha * nu.transpose() * dm;
  L.dnu = (Mat3::Identity() - nu * nu.transpose()) * dm / mu;
}

}  // namespace angio::contact
