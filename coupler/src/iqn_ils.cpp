#include "angio/coupler/iqn_ils.hpp"

#include <stdexcept>

#include "angio/common/log.hpp"
#include "filtered_qr.hpp"

namespace angio::coupler {

void check_iqn_options(const IqnIlsOptions& o, const std::string& method) {
  if (!(o.initial_relaxation > 0.0)) throw std::invalid_argument(method + ": initial relaxation must be > 0");
  if (o.reused_steps < 0 || o.max_columns < 1 || !(o.filter > 0.0 && o.filter < 1.0))
    throw std::invalid_argument(method + ": need reused_steps >= 0, max_columns >= 1, 0 < filter < 1");
  if (!(o.stagnation >= 0.0 && o.stagnation < 1.0)) throw std::invalid_argument(method + ": need 0 <= stagnation < 1");
}

IqnIls::IqnIls(IqnIlsOptions o) : o_(o), factor_(o.initial_relaxation) { check_iqn_options(o_, "IQN-ILS"); }

void IqnIls::begin_step() {
  current_ = Columns{};
  r_prev_.resize(0);
  qt_prev_.resize(0);
}

void IqnIls::restart() {
  begin_step();
  previous_.clear();
}

Eigen::VectorXd IqnIls::update(const Eigen::VectorXd& q, const Eigen::VectorXd& r, int k) {
  const Eigen::VectorXd qt = q + r;
  const std::vector<Eigen::Index> jumped = take_discontinuous();
  if (k > 0 && r_prev_.size() == r.size()) {
    current_.v.insert(current_.v.begin(), r - r_prev_);
    current_.w.insert(current_.w.begin(), qt - qt_prev_);
    drop_rows(current_.v.front(), jumped);
    drop_rows(current_.w.front(), jumped);
  }
  r_prev_ = r;
  qt_prev_ = qt;

  // the columns, newest first, orthogonalized one by one with the QR2 filter
  std::vector<const Eigen::VectorXd*> vs, ws;
  auto take = [&](const Columns& c) {
    for (std::size_t i = 0; i < c.v.size() && int(vs.size()) < o_.max_columns; ++i)
      if (c.v[i].size() == r.size()) {
        vs.push_back(&c.v[i]);
        ws.push_back(&c.w[i]);
      }
  };
  take(current_);
  for (const auto& c : previous_) take(c);

  const FilteredQr qr = filtered_qr(vs, o_.filter);
  last_columns_ = qr.size();
  if (qr.size() == 0) {
    factor_ = o_.initial_relaxation;
    return q + factor_ * r;
  }
  const Eigen::VectorXd alpha = qr.least_squares(r);
  const int m = qr.size();
  Eigen::VectorXd next = qt;
  for (int i = 0; i < m; ++i) next += alpha[i] * *ws[qr.kept[i]];
  factor_ = 1.0;
  // A model step far shorter than the residual means the model claims |1 − λ| > 1/stagnation for
  // the Jacobian eigenvalue λ along r: a column pair that does not belong to this map (a column
  // from before a contact switch, or a difference of r at an unchanged q). Repeating it would
  // return the same iterate forever (the next difference is zero and adds no column), so the
  // model is dropped and the iteration restarts with the initial relaxation.
  if ((next - q).norm() < o_.stagnation * r.norm()) {
    LOG_DEBUG("IQN-ILS: model step " << (next - q).norm() << " against residual " << r.norm()
                                     << ": columns dropped, relaxation " << o_.initial_relaxation);
    current_ = Columns{};
    previous_.clear();
    ++restarts_;
    last_columns_ = 0;
    factor_ = o_.initial_relaxation;
    return q + factor_ * r;
  }
  return next;
}

void IqnIls::end_step(bool accepted) {
  if (accepted && o_.reused_steps > 0 && !current_.v.empty()) {
    previous_.push_front(std::move(current_));
    while (int(previous_.size()) > o_.reused_steps) previous_.pop_back();
  }
  current_ = Columns{};
}

}  // namespace angio::coupler
