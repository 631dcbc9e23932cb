#include "angio/solid/elements.hpp"

#include <cmath>
#include <stdexcept>

namespace angio::solid {

int num_nodes(FaceType t) { return contact::num_nodes(to_contact(t)); }
int num_corners(FaceType t) { return contact::num_corners(to_contact(t)); }
const char* name(ElemType t) {
  switch (t) {
    case ElemType::Hex8:
      return "hex8";
    case ElemType::Tet4:
      return "tet4";
    case ElemType::Tet10:
      return "tet10";
  }
  return "?";
}
const char* name(FaceType t) { return contact::name(to_contact(t)); }

const std::vector<QuadPoint>& volume_rule(ElemType t) {
  static const std::vector<QuadPoint> hex = [] {
    std::vector<QuadPoint> r;
    const double g = 1.0 / std::sqrt(3.0);
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) r.push_back({{i ? g : -g, j ? g : -g, k ? g : -g}, 1.0});
    return r;
  }();
  static const std::vector<QuadPoint> tet1 = {{{0.25, 0.25, 0.25}, 1.0 / 6.0}};
  static const std::vector<QuadPoint> tet4 = [] {
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    return std::vector<QuadPoint>{
        {{b, b, b}, 1.0 / 24.0}, {{a, b, b}, 1.0 / 24.0}, {{b, a, b}, 1.0 / 24.0}, {{b, b, a}, 1.0 / 24.0}};
  }();
  switch (t) {
    case ElemType::Hex8:
      return hex;
    case ElemType::Tet4:
      return tet1;
    case ElemType::Tet10:
      return tet4;
  }
  throw std::logic_error("volume_rule");
}

const std::vector<QuadPoint>& face_rule(FaceType t) {
  // The contact library's tables (one copy of the points and weights): 2x2 Gauss on quads,
  // 3 points on tri3 (degree 2), 6 points on tri6 (degree 4, Dunavant).
  auto from_contact = [](FaceType f, int degree) {
    const contact::QuadratureRule c = contact::face_rule(to_contact(f), degree);
    std::vector<QuadPoint> r;
    for (size_t i = 0; i < c.w.size(); ++i) r.push_back({{c.xi[i](0), c.xi[i](1), 0.0}, c.w[i]});
    return r;
  };
  static const std::vector<QuadPoint> quad = from_contact(FaceType::Quad4, 3), tri3 = from_contact(FaceType::Tri3, 2),
                                      tri6 = from_contact(FaceType::Tri6, 4);
  switch (t) {
    case FaceType::Quad4:
      return quad;
    case FaceType::Tri3:
      return tri3;
    case FaceType::Tri6:
      return tri6;
  }
  throw std::logic_error("face_rule");
}

void shape(ElemType t, const double* xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN) {
  const int n = num_nodes(t);
  N.resize(n);
  dN.resize(n, 3);
  if (t == ElemType::Hex8) {
    static const int s[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    for (int a = 0; a < 8; ++a) {
      const double fx = 1 + s[a][0] * xi[0], fy = 1 + s[a][1] * xi[1], fz = 1 + s[a][2] * xi[2];
      N(a) = 0.125 * fx * fy * fz;
      dN(a, 0) = 0.125 * s[a][0] * fy * fz;
      dN(a, 1) = 0.125 * fx * s[a][1] * fz;
      dN(a, 2) = 0.125 * fx * fy * s[a][2];
    }
    return;
  }
  const double L[4] = {1 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]};
  // dL_i/dxi_j
  static const double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  if (t == ElemType::Tet4) {
    for (int a = 0; a < 4; ++a) {
      N(a) = L[a];
      for (int j = 0; j < 3; ++j) dN(a, j) = dL[a][j];
    }
    return;
  }
  // Tet10 (gmsh): vertices, then edges 01 12 20 30 32 31
  static const int e[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
  for (int a = 0; a < 4; ++a) {
    N(a) = L[a] * (2 * L[a] - 1);
    for (int j = 0; j < 3; ++j) dN(a, j) = (4 * L[a] - 1) * dL[a][j];
  }
  for (int m = 0; m < 6; ++m) {
    const int p = e[m][0], q = e[m][1];
    N(4 + m) = 4 * L[p] * L[q];
    for (int j = 0; j < 3; ++j) dN(4 + m, j) = 4 * (dL[p][j] * L[q] + L[p] * dL[q][j]);
  }
}

void shape(FaceType t, const double* xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN) {
  contact::ShapeN n;
  contact::ShapeD d;
  contact::shape(to_contact(t), contact::Vec2(xi[0], xi[1]), n, &d);
  N = n;
  dN = d;
}

std::vector<Vec3d> reference_nodes(ElemType t) {
  switch (t) {
    case ElemType::Hex8:
      return {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    case ElemType::Tet4:
      return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    case ElemType::Tet10:
      return {{0, 0, 0},     {1, 0, 0},   {0, 1, 0},   {0, 0, 1},     {0.5, 0, 0},
              {0.5, 0.5, 0}, {0, 0.5, 0}, {0, 0, 0.5}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
  }
  return {};
}

const std::vector<LocalFace>& local_faces(ElemType t) {
  static const std::vector<LocalFace> hex = {{FaceType::Quad4, {0, 3, 2, 1}}, {FaceType::Quad4, {4, 5, 6, 7}},
                                             {FaceType::Quad4, {0, 1, 5, 4}}, {FaceType::Quad4, {1, 2, 6, 5}},
                                             {FaceType::Quad4, {2, 3, 7, 6}}, {FaceType::Quad4, {0, 4, 7, 3}}};
  static const std::vector<LocalFace> tet4 = {{FaceType::Tri3, {0, 2, 1}},
                                              {FaceType::Tri3, {0, 1, 3}},
                                              {FaceType::Tri3, {1, 2, 3}},
                                              {FaceType::Tri3, {0, 3, 2}}};
  // tet10 edges: 4:01 5:12 6:20 7:30 8:32 9:31
  static const std::vector<LocalFace> tet10 = {{FaceType::Tri6, {0, 2, 1, 6, 5, 4}},
                                               {FaceType::Tri6, {0, 1, 3, 4, 9, 7}},
                                               {FaceType::Tri6, {1, 2, 3, 5, 8, 9}},
                                               {FaceType::Tri6, {0, 3, 2, 7, 8, 6}}};
  switch (t) {
    case ElemType::Hex8:
      return hex;
    case ElemType::Tet4:
      return tet4;
    case ElemType::Tet10:
      return tet10;
  }
  throw std::logic_error("local_faces");
}

namespace {
// Fixed-size implementation of element_internal for element type T; dN/dxi at the Gauss points is
// cached per element type (not per node count: two types with the same number of nodes, e.g. a
// future wedge or serendipity element, must not share a cache).
template <ElemType T>
bool element_internal_fixed(const Eigen::MatrixXd& Xd, const Eigen::MatrixXd& ud, const NeoHooke& mat,
                            const std::vector<FiberFamily>& fibers, Eigen::VectorXd& f, Eigen::MatrixXd* K,
                            ElementStress* out, const ViscousHistory* visc) {
  constexpr int NN = num_nodes(T);
  constexpr ElemType t = T;
  using MatN3 = Eigen::Matrix<double, NN, 3>;
  using VecF = Eigen::Matrix<double, 3 * NN, 1>;
  using MatK = Eigen::Matrix<double, 3 * NN, 3 * NN>;
  using MatB = Eigen::Matrix<double, 6, 3 * NN>;
  const auto& rule = volume_rule(t);
  static const std::vector<MatN3> dNq = [] {
    std::vector<MatN3> v;
    Eigen::VectorXd N;
    Eigen::MatrixXd dN;
    for (const auto& qp : volume_rule(t)) {
      shape(t, qp.xi, N, dN);
      v.push_back(dN);
    }
    return v;
  }();
  const MatN3 X = Xd, u = ud;
  VecF fe = VecF::Zero();
  MatK Ke;
  if (K) Ke.setZero();
  if (out) *out = ElementStress{};
  MatB B;
  Mat3 S;
  Mat6 D;
  bool ok = true;
  for (size_t q = 0; q < rule.size(); ++q) {
    const MatN3& dN = dNq[q];
    const Mat3 J0 = X.transpose() * dN;
    const double detJ0 = J0.determinant();
    if (!(detJ0 > 0.0)) {
      ok = false;
      continue;
    }
    const MatN3 G = dN * J0.inverse();
    const Mat3 F = Mat3::Identity() + u.transpose() * G;
    const double detF = F.determinant();
    if (!(detF > 0.0)) ok = false;
    const Mat3 C = F.transpose() * F;
    if (visc) {  // S = S∞ + Q (eq. B.8), Q from eq. B.7 integrated over the step
      Vec6 Q, Sv;
      viscous_stress_tangent(mat, fibers, visc->branch, visc->dt, visc->Q_n[q], visc->S_n[q], C, S, K ? &D : nullptr, Q,
                             Sv);
      if (visc->Q_out) visc->Q_out[q] = Q;
      if (visc->S_out) visc->S_out[q] = Sv;
    } else {
      stress_tangent(mat, fibers, C, S, K ? &D : nullptr);
    }
    const double dV = detJ0 * rule[q].w;
    for (int a = 0; a < NN; ++a)
      for (int i = 0; i < 3; ++i) {
        B(0, 3 * a + i) = F(i, 0) * G(a, 0);
        B(1, 3 * a + i) = F(i, 1) * G(a, 1);
        B(2, 3 * a + i) = F(i, 2) * G(a, 2);
        B(3, 3 * a + i) = F(i, 0) * G(a, 1) + F(i, 1) * G(a, 0);
        B(4, 3 * a + i) = F(i, 1) * G(a, 2) + F(i, 2) * G(a, 1);
        B(5, 3 * a + i) = F(i, 0) * G(a, 2) + F(i, 2) * G(a, 0);
      }
    const Vec6 sv = to_voigt_stress(S);
    fe.noalias() += B.transpose() * (sv * dV);
    if (K) {
      const Eigen::Matrix<double, 6, 3 * NN> DB = (D * dV) * B;
      Ke.noalias() += B.transpose() * DB;
      const Eigen::Matrix<double, NN, NN> GSG = G * (S * dV) * G.transpose();
      for (int a = 0; a < NN; ++a)
        for (int b = 0; b < NN; ++b)
          for (int i = 0; i < 3; ++i) Ke(3 * a + i, 3 * b + i) += GSG(a, b);
    }
    if (out) {
      out->cauchy_qp[q] = F * S * F.transpose() / detF;
      out->cauchy_avg += out->cauchy_qp[q];
      out->energy += energy(mat, fibers, C) * dV;
      out->volume += dV;
    }
  }
  if (out) out->cauchy_avg /= double(rule.size());
  f = fe;
  if (K) *K = Ke;
  return ok && f.allFinite();
}
}  // namespace

bool element_internal(ElemType t, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u, const NeoHooke& mat,
                      const std::vector<FiberFamily>& fibers, Eigen::VectorXd& f, Eigen::MatrixXd* K,
                      ElementStress* out, const ViscousHistory* visc) {
  switch (t) {
    case ElemType::Hex8:
      return element_internal_fixed<ElemType::Hex8>(X, u, mat, fibers, f, K, out, visc);
    case ElemType::Tet4:
      return element_internal_fixed<ElemType::Tet4>(X, u, mat, fibers, f, K, out, visc);
    case ElemType::Tet10:
      return element_internal_fixed<ElemType::Tet10>(X, u, mat, fibers, f, K, out, visc);
  }
  return false;
}

void face_pressure(FaceType t, const Eigen::MatrixXd& x, double p, Eigen::VectorXd& r, Eigen::MatrixXd* K) {
  const int n = num_nodes(t);
  r.setZero(3 * n);
  if (K) K->setZero(3 * n, 3 * n);
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (const auto& qp : face_rule(t)) {
    shape(t, qp.xi, N, dN);
    const Vec3d g1 = x.transpose() * dN.col(0);
    const Vec3d g2 = x.transpose() * dN.col(1);
    const Vec3d an = g1.cross(g2);
    for (int a = 0; a < n; ++a) r.segment<3>(3 * a) += p * qp.w * N(a) * an;
    if (K) {
      for (int b = 0; b < n; ++b) {
        const Mat3 dAn = contact::d_area_vector(dN(b, 0), dN(b, 1), g1, g2);
        for (int a = 0; a < n; ++a) K->block<3, 3>(3 * a, 3 * b) += p * qp.w * N(a) * dAn;
      }
    }
  }
}

void face_springs(FaceType t, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u, double k, Eigen::VectorXd& r,
                  Eigen::MatrixXd* K) {
  const int n = num_nodes(t);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (const auto& qp : face_rule(t)) {
    shape(t, qp.xi, N, dN);
    const Vec3d g1 = X.transpose() * dN.col(0);
    const Vec3d g2 = X.transpose() * dN.col(1);
    M += (k * qp.w * g1.cross(g2).norm()) * N * N.transpose();
  }
  r.setZero(3 * n);
  if (K) K->setZero(3 * n, 3 * n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      r.segment<3>(3 * a) += M(a, b) * u.row(b).transpose();
      if (K)
        for (int i = 0; i < 3; ++i) (*K)(3 * a + i, 3 * b + i) += M(a, b);
    }
}

Vec3d face_area_vector(FaceType t, const Eigen::MatrixXd& X) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  Vec3d A = Vec3d::Zero();
  for (const auto& qp : face_rule(t)) {
    shape(t, qp.xi, N, dN);
    const Vec3d g1 = X.transpose() * dN.col(0);
    const Vec3d g2 = X.transpose() * dN.col(1);
    A += qp.w * g1.cross(g2);
  }
  return A;
}

}  // namespace angio::solid
