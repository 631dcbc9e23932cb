// QR factorization of the difference columns of the interface quasi-Newton methods (IQN-ILS,
// IQN-IMVJ), built column by column by modified Gram–Schmidt with the QR2 filter of Haelterman et
// al. (2016): a column is kept if its part orthogonal to the kept (newer) ones exceeds `filter`
// times its norm. Coupler internals.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace angio::coupler {

struct FilteredQr {
  std::vector<Eigen::VectorXd> q;  // orthonormal directions of the kept columns
  Eigen::MatrixXd r;               // upper triangular, kept x kept (top-left block of the allocation)
  std::vector<int> kept;           // indices of the kept columns in the input
  int size() const { return int(q.size()); }
  // α = argmin ||V α + x|| over the kept columns V: R α = −Qᵀ x
  Eigen::VectorXd least_squares(const Eigen::VectorXd& x) const {
    const int m = size();
    Eigen::VectorXd rhs(m);
    for (int i = 0; i < m; ++i) rhs[i] = -q[i].dot(x);
    return r.topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(rhs);
  }
};

inline FilteredQr filtered_qr(const std::vector<const Eigen::VectorXd*>& columns, double filter) {
  FilteredQr out;
  out.r = Eigen::MatrixXd::Zero(columns.size(), columns.size());
  for (std::size_t j = 0; j < columns.size(); ++j) {
    Eigen::VectorXd v = *columns[j];
    const double norm0 = v.norm();
    if (!(norm0 > 0.0)) continue;
    Eigen::VectorXd coeff(out.q.size());
    for (std::size_t i = 0; i < out.q.size(); ++i) {
      coeff[i] = out.q[i].dot(v);
      v -= coeff[i] * out.q[i];
    }
    const double rest = v.norm();
    if (rest < filter * norm0) continue;  // (nearly) dependent on newer columns: drop
    const std::size_t c = out.q.size();
    for (std::size_t i = 0; i < c; ++i) out.r(i, c) = coeff[i];
    out.r(c, c) = rest;
    out.q.push_back(v / rest);
    out.kept.push_back(int(j));
  }
  return out;
}

}  // namespace angio::coupler
