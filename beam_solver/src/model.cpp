#include "angio/beam/model.hpp"

#include "angio/beam/ring_axis.hpp"
#include "angio/common/clock.hpp"
#include "angio/common/log.hpp"
#include "angio/geometry/polyline.hpp"
#include "angio/participant/plane_penalty.hpp"
#include "angio/participant/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace angio::beam {

void gauss_legendre_01(int n, std::vector<double>& xi, std::vector<double>& w) {
  static const std::vector<std::vector<double>> P = {
      {0.0},
      {-0.5773502691896257, 0.5773502691896257},
      {-0.7745966692414834, 0.0, 0.7745966692414834},
      {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526},
      {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640},
      {-0.9324695142031521, -0.6612093864662645, -0.2386191860831969, 0.2386191860831969, 0.6612093864662645,
       0.9324695142031521}};
  static const std::vector<std::vector<double>> W = {
      {2.0},
      {1.0, 1.0},
      {0.5555555555555556, 0.8888888888888888, 0.5555555555555556},
      {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538},
      {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891},
      {0.1713244923791704, 0.3607615730481386, 0.4679139345726910, 0.4679139345726910, 0.3607615730481386,
       0.1713244923791704}};
  if (n < 1 || n > 6) throw std::invalid_argument("sample points per element must be 1..6");
  xi.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    xi[i] = 0.5 * (P[n - 1][i] + 1.0);
    w[i] = 0.5 * W[n - 1][i];
  }
}

Axis::Projection Axis::project(const Vec3& x) const {
  const auto c = geometry::closest_on_polyline(points, x, geometry::PolylineEnds::kExtended);
  Projection p;
  p.foot = c.foot;
  p.tangent = c.tangent;
  p.s = c.s;
  Vec3 rv = x - c.foot;
  rv -= rv.dot(c.tangent) * c.tangent;
  p.r = rv.norm();
  p.radial = p.r > 0 ? Vec3(rv / p.r) : Vec3::Zero();
  return p;
}

int BeamModel::add_node(const Vec3& X) {
  X_.push_back(X);
  basis_.push_back(Mat3::Identity());
  fixed_.push_back({false, false, false, false, false, false});
  return static_cast<int>(X_.size()) - 1;
}

int BeamModel::add_section(const Section& s) {
  sections_.push_back(s);
  return static_cast<int>(sections_.size()) - 1;
}

int BeamModel::add_element(int n1, int n2, int section, const Vec3& up) {
  if (n1 < 0 || n2 < 0 || n1 >= num_nodes() || n2 >= num_nodes() || n1 == n2)
    throw std::invalid_argument("element nodes out of range");
  const Vec3 t = X_[n2] - X_[n1];
  Vec3 u = up;
  if (u.norm() == 0) {
    // default: the global axis least aligned with the element
    Vec3 a = t.cwiseAbs();
    int k = 0;
    a.minCoeff(&k);
    u = Vec3::Unit(k);
  }
  const Quat O = triad_from_tangent(t, u);
  return add_element(n1, n2, section, O, O);
}

int BeamModel::add_element(int n1, int n2, int section, const Quat& O1, const Quat& O2) {
  if (n1 < 0 || n2 < 0 || n1 >= num_nodes() || n2 >= num_nodes() || n1 == n2)
    throw std::invalid_argument("element nodes out of range");
  if (section < 0 || section >= static_cast<int>(sections_.size()))
    throw std::invalid_argument("element section out of range");
  if ((X_[n2] - X_[n1]).norm() <= 0) throw std::invalid_argument("element of zero length");
  elem_nodes_.push_back({n1, n2});
  elem_section_.push_back(section);
  eref_.push_back(make_element_reference(X_[n1], X_[n2], O1, O2));
  return static_cast<int>(elem_nodes_.size()) - 1;
}

void BeamModel::fix(int node, const std::array<bool, 6>& f) {
  for (int i = 0; i < 6; ++i) fixed_.at(node)[i] = fixed_.at(node)[i] || f[i];
}

namespace {
// Translation basis (radial, circumferential, axial) at a point projected onto the axis; on the
// axis the radial direction is an arbitrary normal.
Mat3 cylindrical_basis(const Axis::Projection& p) {
  Mat3 B;
  if (p.r > 0) {
    B.col(0) = p.radial;
  } else {
    B.col(0) = triad_from_tangent(p.tangent, Vec3::UnitX()).toRotationMatrix().col(1);
  }
  B.col(1) = p.tangent.cross(B.col(0));
  B.col(2) = p.tangent;
  return B;
}
}  // namespace

// Circumferential fixation (alone or with the axial one: radial-only motion) needs the node's
// radial direction, i.e. a node off the axis.
void BeamModel::fix_cylindrical(int node, bool circumferential, bool axial) {
  const auto p = axis.project(X_.at(node));
  if (circumferential && p.r <= 1e-12)
    throw std::invalid_argument("node " + std::to_string(node) + " lies on the device axis");
  basis_[node] = cylindrical_basis(p);
  fixed_[node][1] = fixed_[node][1] || circumferential;
  fixed_[node][2] = fixed_[node][2] || axial;
}

void BeamModel::finalize() {
  const int n = num_nodes();
  free_.assign(n, {-1, -1, -1, -1, -1, -1});
  nfree_ = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 6; ++k)
      if (!fixed_[i][k]) free_[i][k] = nfree_++;
  for (const auto& pr : prescribed_rotations)
    if (!(fixed_.at(pr.node)[3] && fixed_[pr.node][4] && fixed_[pr.node][5]))
      throw std::invalid_argument("prescribed rotation needs all rotations of the node fixed");
  for (const auto& pd : prescribed_displacements)
    if (!fixed_.at(pd.node).at(pd.comp)) throw std::invalid_argument("prescribed displacement on a free DOF");
  x_ = xc_ = X_;
  R_.assign(n, Quat::Identity());
  Rc_ = R_;
  mp_committed_.assign(num_elements(), PlasticState{});
  mp_trial_ = mp_committed_;
  mnorm_.assign(num_elements(), 0.0);
  stress_.assign(num_elements(), Vec6::Zero());
  gauss_legendre_01(sample_points_per_element, gauss_xi_, gauss_w_);
  q_ext_.assign(num_sample_points(), Vec3::Zero());
  ref_radial_.assign(num_sample_points(), Vec3::Zero());
  for (int g = 0; g < num_sample_points(); ++g) {
    const int e = g / sample_points_per_element, k = g % sample_points_per_element;
    const auto [a, b] = elem_nodes_[e];
    ref_radial_[g] = axis.project((1.0 - gauss_xi_[k]) * X_[a] + gauss_xi_[k] * X_[b]).radial;
  }
  identity_basis_.assign(n, 1);
  for (int i = 0; i < n; ++i) identity_basis_[i] = basis_[i].isIdentity(0.0) ? 1 : 0;
  elem_dofs_.resize(12 * static_cast<size_t>(num_elements()));
  for (int e = 0; e < num_elements(); ++e)
    for (int k = 0; k < 6; ++k) {
      elem_dofs_[12 * e + k] = free_[elem_nodes_[e][0]][k];
      elem_dofs_[12 * e + 6 + k] = free_[elem_nodes_[e][1]][k];
    }
  pattern_ = SpMat();
  elem_pos_.clear();
  lin_.reset();
}

Vec6 BeamModel::strain(int e) const {
  const auto [a, b] = elem_nodes_[e];
  return element_strain(eref_[e], x_[a], x_[b], R_[a], R_[b]);
}

Vec3 BeamModel::sample_position(int g) const {
  const int e = g / sample_points_per_element, k = g % sample_points_per_element;
  const auto [a, b] = elem_nodes_[e];
  return (1.0 - gauss_xi_[k]) * x_[a] + gauss_xi_[k] * x_[b];
}
double BeamModel::sample_weight(int g) const {
  const int e = g / sample_points_per_element, k = g % sample_points_per_element;
  return gauss_w_[k] * eref_[e].L0;
}
double BeamModel::sample_radius(int g) const { return element_section(g / sample_points_per_element).contact_radius; }
void BeamModel::set_sample_line_loads(const std::vector<Vec3>& q) {
  if (static_cast<int>(q.size()) != num_sample_points())
    throw std::invalid_argument("expected " + std::to_string(num_sample_points()) + " sample line loads, got " +
                                std::to_string(q.size()));
  q_ext_ = q;
}
void BeamModel::set_sample_planes(std::vector<SamplePlane> planes) {
  const std::size_t K = participant::planes_per_point(planes.size(), std::size_t(num_sample_points()));
  if (!planes.empty() && K == 0)
    throw std::invalid_argument("expected K x " + std::to_string(num_sample_points()) + " contact planes, got " +
                                std::to_string(planes.size()));
  planes_ = std::move(planes);
  planes_per_point_ = int(K);
}
std::vector<Vec3> BeamModel::sample_contact_loads() const {
  std::vector<Vec3> q = q_ext_;
  for (size_t i = 0; i < planes_.size(); ++i) {
    const int g = int(i) / planes_per_point_;
    q[g] += participant::plane_penalty(sample_position(g), planes_[i].s, planes_[i].n, planes_[i].eps, sample_radius(g),
                                       planes_[i].g0)
                .q;
  }
  return q;
}
std::vector<Vec3> BeamModel::sample_load_nodal_forces() const {
  std::vector<Vec3> f(num_nodes(), Vec3::Zero());
  const std::vector<Vec3> q = sample_contact_loads();
  for (int g = 0; g < num_sample_points(); ++g) {
    const int e = g / sample_points_per_element, k = g % sample_points_per_element;
    const auto [a, b] = elem_nodes_[e];
    const double w = sample_weight(g);
    f[a] += (1.0 - gauss_xi_[k]) * w * q[g];
    f[b] += gauss_xi_[k] * w * q[g];
  }
  return f;
}

double BeamModel::diameter(bool reference) const { return mean_diameter(axis, positions(reference)); }

void BeamModel::set_time(double t) {
  time_ = t;
  for (const auto& pd : prescribed_displacements) {
    const Vec3 b = basis_[pd.node].col(pd.comp);
    const double target = pd.value * pd.curve(t);
    const double cur = b.dot(x_[pd.node] - X_[pd.node]);
    x_[pd.node] += (target - cur) * b;
  }
  for (const auto& pr : prescribed_rotations) R_[pr.node] = quat_exp(pr.value * pr.curve(t));
}

void BeamModel::set_state(const std::vector<Vec3>& x, const std::vector<Quat>& R) {
  x_ = x;
  R_ = R;
}

void BeamModel::start_from(double t, const std::vector<Vec3>& x, const std::vector<Quat>& R,
                           const std::vector<PlasticState>& plastic) {
  xc_ = x_ = x;
  Rc_ = R_ = R;
  mp_committed_ = mp_trial_ = plastic;
  set_time(t);
  xc_ = x_;
}

void BeamModel::assemble(SpMat* K, Eigen::VectorXd& r) {
  Eigen::VectorXd rg;
  assemble_global(K, rg);
  // reduce the residual to the free DOFs in the nodes' bases
  r.setZero(nfree_);
  for (int n = 0; n < num_nodes(); ++n) {
    const Vec3 rt = basis_[n].transpose() * rg.segment<3>(6 * n);
    for (int k = 0; k < 3; ++k) {
      if (free_[n][k] >= 0) r(free_[n][k]) = rt(k);
      if (free_[n][3 + k] >= 0) r(free_[n][3 + k]) = rg(6 * n + 3 + k);
    }
  }
}

Eigen::VectorXd BeamModel::global_residual() {
  Eigen::VectorXd rg;
  assemble_global(nullptr, rg);
  return rg;
}

void BeamModel::assemble_global(SpMat* K, Eigen::VectorXd& rg) {
  if (nfree_ < 0) throw std::logic_error("BeamModel::finalize() not called");
  const int ne = num_elements();
  rg.setZero(6 * num_nodes());
  // distributed loads at this time
  elem_q_.assign(ne, Vec3::Zero());
  elem_p_follower_.assign(ne, 0.0);
  elem_p_dead_.assign(ne, 0.0);
  for (const auto& l : line_loads) {
    const Vec3 q = l.q * l.curve(time_);
    if (l.elements.empty())
      for (auto& v : elem_q_) v += q;
    else
      for (int e : l.elements) elem_q_.at(e) += q;
  }
  for (const auto& l : radial_loads) {
    const double p = l.p * l.curve(time_);
    auto& tgt = l.follower ? elem_p_follower_ : elem_p_dead_;
    if (l.elements.empty())
      for (auto& v : tgt) v += p;
    else
      for (int e : l.elements) tgt.at(e) += p;
  }
  const int ng = sample_points_per_element;
  // The first assembly with a tangent collects triplets and builds the pattern; later ones add
  // into the pattern's values at the positions found then.
  const bool first_pattern = K && elem_pos_.empty();
  std::vector<Eigen::Triplet<double>> trip;
  if (first_pattern) trip.reserve(static_cast<size_t>(ne) * 144);
  double* vals = nullptr;
  if (K && !first_pattern) {
    *K = pattern_;
    vals = K->valuePtr();
    std::fill(vals, vals + K->nonZeros(), 0.0);
  }
  auto scatter = [&](int e, const Mat12& Km) {
    if (first_pattern) {
      const int* idx = &elem_dofs_[12 * static_cast<size_t>(e)];
      for (int i = 0; i < 12; ++i) {
        if (idx[i] < 0) continue;
        for (int j = 0; j < 12; ++j)
          if (idx[j] >= 0) trip.emplace_back(idx[i], idx[j], Km(i, j));
      }
    } else {
      const int* pos = &elem_pos_[144 * static_cast<size_t>(e)];
      for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j)
          if (pos[12 * i + j] >= 0) vals[pos[12 * i + j]] += Km(i, j);
    }
  };
  // Element kernels are independent: evaluate them in parallel (OpenMP, when available), then
  // add loads and scatter serially.
  elem_results_.resize(ne);
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (ne >= 64)
#endif
  for (int e = 0; e < ne; ++e) {
    const auto [a, b] = elem_nodes_[e];
    elem_results_[e] = evaluate_element(sections_[elem_section_[e]], eref_[e], x_[a], x_[b], R_[a], R_[b],
                                        mp_committed_[e], K != nullptr, residual_form);
  }
  for (int e = 0; e < ne; ++e) {
    const auto [a, b] = elem_nodes_[e];
    ElementResult& ev = elem_results_[e];
    mp_trial_[e] = ev.section.state;
    mnorm_[e] = ev.section.bending_moment_norm;
    stress_[e] = ev.section.stress;
    Vec12& re = ev.residual;
    Mat12& Ke = ev.tangent;
    // load stiffness of a sample point's line load q(x), x = N1 x_a + N2 x_b
    auto add_load_stiffness = [&](double N1, double N2, double w, const Mat3& dq_dx) {
      Ke.block<3, 3>(0, 0) -= N1 * N1 * w * dq_dx;
      Ke.block<3, 3>(0, 6) -= N1 * N2 * w * dq_dx;
      Ke.block<3, 3>(6, 0) -= N2 * N1 * w * dq_dx;
      Ke.block<3, 3>(6, 6) -= N2 * N2 * w * dq_dx;
    };
    for (int k = 0; k < ng; ++k) {
      const int g = e * ng + k;
      const double N2 = gauss_xi_[k], N1 = 1.0 - N2;
      const double w = gauss_w_[k] * eref_[e].L0;
      Vec3 q = q_ext_[g] + elem_q_[e] + elem_p_dead_[e] * ref_radial_[g];
      for (int j = 0; j < planes_per_point_; ++j) {  // 0 without planes
        const SamplePlane& pl = planes_[g * planes_per_point_ + j];
        if (!(pl.eps > 0.0)) continue;
        const participant::PlanePenalty pp = participant::plane_penalty(
            N1 * x_[a] + N2 * x_[b], pl.s, pl.n, pl.eps, sections_[elem_section_[e]].contact_radius, pl.g0);
        q += pp.q;
        if (K) add_load_stiffness(N1, N2, w, pp.dq_dx);  // zero where the point is free
      }
      if (const double p = elem_p_follower_[e]; p != 0.0) {
        const auto pr = axis.project(N1 * x_[a] + N2 * x_[b]);
        q += p * pr.radial;
        if (K && pr.r > 0) {
          const Mat3 P = Mat3::Identity() - pr.tangent * pr.tangent.transpose();
          add_load_stiffness(N1, N2, w, p / pr.r * (P - pr.radial * pr.radial.transpose()));
        }
      }
      re.segment<3>(0) -= N1 * w * q;
      re.segment<3>(6) -= N2 * w * q;
    }
    rg.segment<6>(6 * a) += re.segment<6>(0);
    rg.segment<6>(6 * b) += re.segment<6>(6);
    if (K) {
      // translations of a node with a local basis B: K ← Tᵀ K T, T = diag(B_a, I, B_b, I)
      for (int side = 0; side < 2; ++side) {
        const int n = elem_nodes_[e][side];
        if (identity_basis_[n]) continue;
        Ke.middleRows<3>(6 * side) = basis_[n].transpose() * Ke.middleRows<3>(6 * side);
        Ke.middleCols<3>(6 * side) = Ke.middleCols<3>(6 * side) * basis_[n];
      }
      scatter(e, Ke);
    }
  }
  for (const auto& l : nodal_loads) {
    const double c = l.curve(time_);
    rg.segment<3>(6 * l.node) -= c * l.force;
    rg.segment<3>(6 * l.node + 3) -= c * l.moment;
  }
  if (first_pattern) {
    pattern_.resize(nfree_, nfree_);
    pattern_.setFromTriplets(trip.begin(), trip.end());
    pattern_.makeCompressed();
    *K = pattern_;
    // positions of every element entry in the compressed pattern, for the next assemblies
    elem_pos_.assign(static_cast<size_t>(ne) * 144, -1);
    const int* outer = pattern_.outerIndexPtr();
    const int* inner = pattern_.innerIndexPtr();
    for (int e = 0; e < ne; ++e) {
      const int* idx = &elem_dofs_[12 * static_cast<size_t>(e)];
      for (int i = 0; i < 12; ++i) {
        if (idx[i] < 0) continue;
        for (int j = 0; j < 12; ++j) {
          if (idx[j] < 0) continue;
          // column idx[j], row idx[i]
          const int* lo = inner + outer[idx[j]];
          const int* hi = inner + outer[idx[j] + 1];
          const int* it = std::lower_bound(lo, hi, idx[i]);
          elem_pos_[144 * e + 12 * i + j] = static_cast<int>(it - inner);
        }
      }
    }
  }
}

void BeamModel::apply_increment(const Eigen::VectorXd& d, double alpha) {
  for (int n = 0; n < num_nodes(); ++n) {
    Vec3 dx = Vec3::Zero(), dth = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      if (free_[n][k] >= 0) dx += d(free_[n][k]) * basis_[n].col(k);
      if (free_[n][3 + k] >= 0) dth(k) = d(free_[n][3 + k]);
    }
    x_[n] += alpha * dx;
    if (dth.squaredNorm() > 0) R_[n] = (quat_exp(alpha * dth) * R_[n]).normalized();
  }
}

bool BeamModel::ResponseTangent::matches(const BeamModel& m) const {
  if (!lin || time != m.time_ || x != m.x_ || q != m.q_ext_ || planes.size() != m.planes_.size()) return false;
  for (std::size_t i = 0; i < R.size(); ++i)
    if (R[i].coeffs() != m.R_[i].coeffs()) return false;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const SamplePlane &a = planes[i], &b = m.planes_[i];
    if (a.s != b.s || a.n != b.n || a.eps != b.eps || a.g0 != b.g0) return false;
  }
  return true;
}

std::vector<Vec3> BeamModel::plane_response(const std::vector<double>& shift, const std::vector<Vec3>& turn) {
  if (shift.size() != planes_.size() || (!turn.empty() && turn.size() != planes_.size()))
    throw std::invalid_argument("expected one shift (and none or one turn) per contact plane (" +
                                std::to_string(planes_.size()) + "), got " + std::to_string(shift.size()) + " and " +
                                std::to_string(turn.size()));
  std::vector<Vec3> dx(num_sample_points(), Vec3::Zero());
  double smax = 0.0;
  for (double v : shift) smax = std::max(smax, std::abs(v));
  for (const Vec3& t : turn) smax = std::max(smax, t.cwiseAbs().maxCoeff());
  if (!(smax > 0.0)) return dx;
  if (!response_.matches(*this)) {  // the products of one coupling iteration share one factorization
    if (!response_.lin) response_.lin = make_linear_solver(newton.linear_solver);
    assemble(&response_.K, response_.r);
    response_.lin->factorize(response_.K);
    response_.x = x_;
    response_.R = R_;
    response_.q = q_ext_;
    response_.planes = planes_;
    response_.time = time_;
  }
  // ∂r/∂(shift, turn) by forward differences of the residual in the planes alone (the state does not
  // move, so the elements' trial states stay those of the current state): exact in the shift for the
  // linear penalty law and for the quadratic part of the regularized one, O(h) in the turn; 1e-6
  // against positions of order 1 mm leaves round-off of about 1e-10 relative.
  const double h = 1e-6 / smax;
  const std::vector<SamplePlane> planes = planes_;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    planes_[i].s = planes[i].s + h * shift[i] * planes[i].n;
    if (!turn.empty()) planes_[i].n = planes[i].n + h * turn[i];
  }
  Eigen::VectorXd rp;
  assemble(nullptr, rp);
  planes_ = planes;
  const Eigen::VectorXd du = response_.lin->solve(-(rp - response_.r) / h);
  // sample positions are linear in the nodes' positions: one whole increment gives them exactly
  const std::vector<Vec3> xs = x_;
  const std::vector<Quat> Rs = R_;
  std::vector<Vec3> x0(dx.size());
  for (int g = 0; g < num_sample_points(); ++g) x0[g] = sample_position(g);
  apply_increment(du, 1.0);
  for (int g = 0; g < num_sample_points(); ++g) dx[g] = sample_position(g) - x0[g];
  x_ = xs;
  R_ = Rs;
  return dx;
}

void BeamModel::commit() {
  xc_ = x_;
  Rc_ = R_;
  mp_committed_ = mp_trial_;
}

void BeamModel::restore() {
  x_ = xc_;
  R_ = Rc_;
  mp_trial_ = mp_committed_;
}

NewtonStats BeamModel::solve() {
  const auto t0 = Clock::now();
  NewtonStats st;
  if (!lin_) lin_ = make_linear_solver(newton.linear_solver);
  SpMat K;
  Eigen::VectorXd r;
  assemble(&K, r);
  double rn = r.norm();
  const double r0 = rn;
  st.residual_history.push_back(rn);
  auto finish = [&](bool ok, const std::string& msg) {
    st.converged = ok;
    st.residual = rn;
    st.message = msg;
    st.seconds = seconds_since(t0);
    return st;
  };
  if (!std::isfinite(rn)) return finish(false, "residual is NaN/Inf at the start of the solve");
  const double rtol = std::max(newton.residual_tol, newton.residual_rel_tol * r0);
  if (rn <= newton.residual_tol) return finish(true, "");
  double dn = std::numeric_limits<double>::infinity();
  Eigen::VectorXd rnew;
  SpMat Knew;
  for (int it = 1; it <= newton.max_iterations; ++it) {
    Eigen::VectorXd d;
    try {
      d = lin_->solve(K, -r);
    } catch (const std::exception& e) {
      return finish(false, std::string("linear solve failed in iteration ") + std::to_string(it) + ": " + e.what() +
                               "; residual history: " + log::list(st.residual_history));
    }
    if (!d.allFinite()) return finish(false, "Newton increment is NaN/Inf in iteration " + std::to_string(it));
    const auto xs = x_;
    const auto Rs = R_;
    double alpha = 1.0;
    for (int ls = 0;; ++ls) {
      apply_increment(d, alpha);
      assemble(&Knew, rnew);
      const double rnn = rnew.norm();
      // Energy-norm line search (Crisfield): accept if the residual norm or the work of the
      // residual along the increment |d·r(α)| decreases; beams mix stiff axial and soft bending
      // modes, so the plain residual norm is a poor merit function early in the iteration.
      const bool ok =
          std::isfinite(rnn) && (!newton.line_search || rnn <= rn || std::abs(d.dot(rnew)) <= std::abs(d.dot(r)));
      if (ok || ls >= newton.max_line_search) {
        if (!std::isfinite(rnn)) {
          rn = rnn;
          st.iterations = it;
          return finish(false, "residual became NaN/Inf in iteration " + std::to_string(it));
        }
        break;
      }
      x_ = xs;
      R_ = Rs;
      alpha *= 0.5;
    }
    std::swap(K, Knew);  // Knew keeps its storage for the next assembly
    std::swap(r, rnew);
    rn = r.norm();
    dn = alpha * d.norm();
    st.iterations = it;
    st.residual_history.push_back(rn);
    st.increment_history.push_back(dn);
    if (rn > 1e8 * std::max(r0, newton.residual_tol))
      return finish(false,
                    "Newton diverged in iteration " + std::to_string(it) +
                        " (residual grew by more than 1e8); residual history: " + log::list(st.residual_history));
    if (rn <= rtol && dn <= newton.increment_tol) return finish(true, "");
    // round-off floor: increment negligible and residual within 100× the tolerance
    if (dn <= 1e-3 * newton.increment_tol && rn <= 100.0 * rtol) return finish(true, "");
  }
  return finish(false, "Newton did not converge in " + std::to_string(newton.max_iterations) +
                           " iterations; residual history: " + log::list(st.residual_history) + "; last increment " +
                           std::to_string(dn));
}

}  // namespace angio::beam
