#include "angio/coupler/iqn_imvj.hpp"

#include "angio/common/log.hpp"
#include "filtered_qr.hpp"

namespace angio::coupler {

IqnImvj::IqnImvj(IqnIlsOptions o) : o_(o), factor_(o.initial_relaxation) { check_iqn_options(o_, "IQN-IMVJ"); }

void IqnImvj::begin_step() {
  v_.clear();
  w_.clear();
  d_.clear();
  r_prev_.resize(0);
  qt_prev_.resize(0);
  last_ = Correction{};
  last_kept_.clear();
}

void IqnImvj::restart() {
  begin_step();
  prev_.clear();
}

Eigen::VectorXd IqnImvj::apply_prev_(const Eigen::VectorXd& x) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(x.size());
  for (const auto& c : prev_)
    if (c.b.rows() == x.size()) y.noalias() += c.a * (c.b.transpose() * x);
  return y;
}

Eigen::MatrixXd IqnImvj::times_r_inverse_(const std::vector<Eigen::VectorXd>& columns) const {
  const int m = int(last_kept_.size());
  Eigen::MatrixXd x(columns.front().size(), m);
  for (int i = 0; i < m; ++i) x.col(i) = columns[last_kept_[i]];
  // y R = x  ⇔  Rᵀ yᵀ = xᵀ
  return last_r_.triangularView<Eigen::Upper>().transpose().solve(x.transpose()).transpose();
}

Eigen::VectorXd IqnImvj::update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) {
  const Eigen::VectorXd qt = q + r;
  const std::vector<Eigen::Index> jumped = take_discontinuous();
  if (k > 0 && r_prev_.size() == r.size()) {
    v_.insert(v_.begin(), r - r_prev_);
    w_.insert(w_.begin(), qt - qt_prev_);
    drop_rows(v_.front(), jumped);
    drop_rows(w_.front(), jumped);
    d_.insert(d_.begin(), w_.front() - apply_prev_(v_.front()));  // J_prev is fixed within the step
  }
  r_prev_ = r;
  qt_prev_ = qt;
  std::vector<const Eigen::VectorXd*> vs;
  for (std::size_t i = 0; i < v_.size() && int(vs.size()) < o_.max_columns; ++i) vs.push_back(&v_[i]);
  const FilteredQr qr = filtered_qr(vs, o_.filter);
  last_columns_ = qr.size();
  const bool carried = !prev_.empty();
  if (qr.size() == 0 && !carried) {  // nothing known yet: relax
    factor_ = o_.initial_relaxation;
    last_ = Correction{};
    return q + factor_ * r;
  }
  Eigen::VectorXd jr = apply_prev_(r);
  const int m = qr.size();
  last_ = Correction{};
  last_kept_ = qr.kept;
  last_r_ = qr.r.topLeftCorner(m, m);
  if (m > 0) {
    // a = (W − J_prev V) R⁻¹ over the kept columns, b = Q: J = J_prev + a bᵀ
    last_.a = times_r_inverse_(d_);
    last_.b.resize(r.size(), m);
    for (int i = 0; i < m; ++i) last_.b.col(i) = qr.q[i];
    jr.noalias() += last_.a * (last_.b.transpose() * r);
  }
  const Eigen::VectorXd next = qt - jr;
  factor_ = 1.0;
  // as IQN-ILS: a model step far shorter than the residual does not belong to this map
  if ((next - q).norm() < o_.stagnation * r.norm()) {
    LOG_DEBUG("IQN-IMVJ: model step " << (next - q).norm() << " against residual " << r.norm()
                                      << ": Jacobian dropped, relaxation " << o_.initial_relaxation);
    v_.clear();
    w_.clear();
    d_.clear();
    prev_.clear();
    last_ = Correction{};
    last_kept_.clear();
    ++restarts_;
    last_columns_ = 0;
    factor_ = o_.initial_relaxation;
    return q + factor_ * r;
  }
  return next;
}

void IqnImvj::end_step(bool accepted) {
  if (accepted && o_.reused_steps > 0 && last_.a.cols() > 0) {
    if (int(prev_.size()) >= o_.reused_steps) {  // restart from 0 (RS-ZERO) with this step's own model
      prev_.clear();
      last_.a = times_r_inverse_(w_);  // the correction from J_prev = 0: W R⁻¹, IQN-ILS's model
    }
    prev_.push_back(std::move(last_));
  }
  begin_step();
}

}  // namespace angio::coupler
