#include "angio/solid/recovery_kernels.hpp"

#include <stdexcept>

namespace angio::solid {

const std::vector<QuadPoint>& recovery_rule(ElemType t) {
  // 14-point degree-5 rule on the unit tetrahedron (Walkington; positive weights, summing to 1/6):
  // 4 points (a, a, a, 1 − 3a) twice, 6 points (c, c, d, d) with d = 1/2 − c.
  static const std::vector<QuadPoint> tet14 = [] {
    std::vector<QuadPoint> r;
    auto four = [&](double a, double w) {
      const double o = 1.0 - 3.0 * a;
      r.push_back({{a, a, a}, w});
      r.push_back({{o, a, a}, w});
      r.push_back({{a, o, a}, w});
      r.push_back({{a, a, o}, w});
    };
    four(0.0927352503108912264, 0.01224884051939365826);
    four(0.3108859192633006097, 0.01878132095300264180);
    const double c = 0.4544962958743503956, d = 0.5 - c, w = 0.007091003462846911495;
    // barycentric (c, c, d, d) and its permutations: the 6 ways to pick the two coordinates equal to c
    const double bary[6][4] = {{c, c, d, d}, {c, d, c, d}, {c, d, d, c}, {d, c, c, d}, {d, c, d, c}, {d, d, c, c}};
    for (const auto& l : bary) r.push_back({{l[1], l[2], l[3]}, w});
    return r;
  }();
  static const std::vector<QuadPoint> tet4 = volume_rule(ElemType::Tet10);  // the 4-point degree-2 rule
  switch (t) {
    case ElemType::Hex8:
      return volume_rule(ElemType::Hex8);
    case ElemType::Tet4:
      return tet4;
    case ElemType::Tet10:
      return tet14;
  }
  throw std::logic_error("recovery_rule");
}

namespace {
// Basis of the Gauss-point interpolant σ_h at a reference point: hex8 trilinear, tet10 linear,
// tet4 constant (as many functions as Gauss points, so the interpolant is unique).
Eigen::RowVectorXd interpolant_basis(ElemType t, const double* xi) {
  const double x = xi[0], y = xi[1], z = xi[2];
  Eigen::RowVectorXd p;
  switch (t) {
    case ElemType::Hex8:
      p.resize(8);
      p << 1, x, y, z, x * y, y * z, x * z, x * y * z;
      break;
    case ElemType::Tet10:
      p.resize(4);
      p << 1, x, y, z;
      break;
    case ElemType::Tet4:
      p.resize(1);
      p << 1;
      break;
  }
  return p;
}

// Per element type: shape functions at the recovery points and the matrix Φ (points × Gauss
// points) that evaluates σ_h there: σ_h(ξ_p) = Σ_q Φ_pq σ_q.
struct RecoveryCache {
  std::vector<Eigen::VectorXd> N;
  std::vector<Eigen::MatrixXd> dN;
  Eigen::MatrixXd phi;
};
const RecoveryCache& cache(ElemType t) {
  auto build = [](ElemType t) {
    RecoveryCache c;
    const auto& rule = recovery_rule(t);
    const auto& gauss = volume_rule(t);
    Eigen::MatrixXd Pr(rule.size(), gauss.size()), Pg(gauss.size(), gauss.size());
    for (size_t p = 0; p < rule.size(); ++p) {
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      shape(t, rule[p].xi, N, dN);
      c.N.push_back(N);
      c.dN.push_back(dN);
      Pr.row(p) = interpolant_basis(t, rule[p].xi);
    }
    for (size_t q = 0; q < gauss.size(); ++q) Pg.row(q) = interpolant_basis(t, gauss[q].xi);
    c.phi = Pr * Pg.inverse();
    return c;
  };
  static const RecoveryCache hex = build(ElemType::Hex8), tet4 = build(ElemType::Tet4), tet10 = build(ElemType::Tet10);
  switch (t) {
    case ElemType::Hex8:
      return hex;
    case ElemType::Tet4:
      return tet4;
    case ElemType::Tet10:
      return tet10;
  }
  throw std::logic_error("recovery cache");
}
}  // namespace

double recovery_element(ElemType t, const Eigen::MatrixXd& X, const Mat3* gauss_stress, Eigen::MatrixXd* M,
                        Eigen::MatrixXd* b) {
  const int n = num_nodes(t);
  if (X.rows() != n || X.cols() != 3) throw std::invalid_argument("recovery_element: X must be n x 3");
  const auto& rule = recovery_rule(t);
  const RecoveryCache& c = cache(t);
  const bool rhs = b && gauss_stress;
  if (M) M->setZero(n, n);
  if (rhs) b->setZero(n, 6);
  const int nq = int(c.phi.cols());
  double volume = 0.0;
  for (size_t p = 0; p < rule.size(); ++p) {
    const double dV = (X.transpose() * c.dN[p]).determinant() * rule[p].w;
    volume += dV;
    const Eigen::VectorXd& N = c.N[p];
    if (M) M->noalias() += (dV * N) * N.transpose();
    if (rhs) {
      Mat3 s = Mat3::Zero();
      for (int q = 0; q < nq; ++q) s += c.phi(p, q) * gauss_stress[q];
      Eigen::Matrix<double, 1, 6> v;
      for (int k = 0; k < 6; ++k) v(k) = s(kVoigt[k][0], kVoigt[k][1]);
      b->noalias() += (dV * N) * v;
    }
  }
  return volume;
}

}  // namespace angio::solid
