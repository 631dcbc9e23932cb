#include "angio/beam/element.hpp"

#include <cmath>

#include "angio/beam/dual.hpp"

namespace angio::beam {

namespace {

template <class T>
struct Q {
  T w, x, y, z;
};

template <class T>
Q<T> qmul(const Q<T>& a, const Q<T>& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + b.w * a.x + (a.y * b.z - a.z * b.y),
          a.w * b.y + b.w * a.y + (a.z * b.x - a.x * b.z), a.w * b.z + b.w * a.z + (a.x * b.y - a.y * b.x)};
}
template <class T>
Q<T> qconst(const Quat& q) {
  return {T(q.w()), T(q.x()), T(q.y()), T(q.z())};
}
template <class T>
Q<T> qconj(const Q<T>& a) {
  return {a.w, -a.x, -a.y, -a.z};
}
template <class T>
Q<T> qnormalize(const Q<T>& a) {
  using std::sqrt;
  T n = sqrt(a.w * a.w + a.x * a.x + a.y * a.y + a.z * a.z);
  T in = T(1.0) / n;
  return {a.w * in, a.x * in, a.y * in, a.z * in};
}
// First-order exponential map of a (value-zero) perturbation: exact for first and mixed
// second derivatives, which is all the tangent needs.
template <class T>
Q<T> qsmall(const T* th) {
  return {T(1.0), th[0] * 0.5, th[1] * 0.5, th[2] * 0.5};
}
// Relative rotation of the two element triads (Crisfield–Jelenić): φ = log(Λ1ᵀΛ2) (in the Λ1
// frame) and the reference triad Λ_r = Λ1 exp(φ/2), with sqrt(q) = normalize(1 + q) for the
// shortest-arc quaternion.
template <class T>
void relative_rotation(const Q<T>& L1, const Q<T>& L2, T* phi, Q<T>& qr) {
  using std::atan2;
  using std::sqrt;
  Q<T> rel = qmul(qconj(L1), L2);
  if (val(rel.w) < 0.0) rel = {-rel.w, -rel.x, -rel.y, -rel.z};
  // φ = log(rel) = 2 atan2(|v|, w) v/|v| (series for small |v| keeps the derivatives finite)
  T s = rel.x * rel.x + rel.y * rel.y + rel.z * rel.z;
  T f;
  const double sv = val(s), wv = val(rel.w);
  if (sv < 1e-16 * wv * wv) {
    T t2 = s / (rel.w * rel.w);
    f = (1.0 - t2 / 3.0) / rel.w;
  } else {
    T nv = sqrt(s);
    f = atan2(nv, rel.w) / nv;
  }
  phi[0] = 2.0 * f * rel.x;
  phi[1] = 2.0 * f * rel.y;
  phi[2] = 2.0 * f * rel.z;
  qr = qmul(L1, qnormalize(Q<T>{rel.w + 1.0, rel.x, rel.y, rel.z}));
}

// Rotation part only: perturbations of the two nodal rotations (6 variables each set).
// Returns φ (relative rotation vector, Λ1 frame) and Q = Λ_rᵀ as a row-major 3×3.
template <class T>
void rotation_kernel(const ElementReference& ref, const Quat& R1, const Quat& R2, const T* pe, const T* pd, T* phi,
                     T* Qm) {
  Q<T> L1 = qnormalize(qmul(qmul(qsmall(pe), qsmall(pd)), qconst<T>(R1 * ref.O1)));
  Q<T> L2 = qnormalize(qmul(qmul(qsmall(pe + 3), qsmall(pd + 3)), qconst<T>(R2 * ref.O2)));
  Q<T> qr;
  relative_rotation(L1, L2, phi, qr);
  qr = qnormalize(qr);
  // Λ_rᵀ = (w² − v·v) I + 2 v vᵀ − 2 w [v]×
  const T a = qr.w * qr.w - (qr.x * qr.x + qr.y * qr.y + qr.z * qr.z);
  const T v[3] = {qr.x, qr.y, qr.z};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Qm[3 * i + j] = 2.0 * (v[i] * v[j]);
  for (int i = 0; i < 3; ++i) Qm[4 * i] = Qm[4 * i] + a;
  const T wx = 2.0 * (qr.w * v[0]), wy = 2.0 * (qr.w * v[1]), wz = 2.0 * (qr.w * v[2]);
  // −2w[v]×: [v]× = [[0,−z,y],[z,0,−x],[−y,x,0]]
  Qm[1] = Qm[1] + wz;
  Qm[2] = Qm[2] - wy;
  Qm[3] = Qm[3] - wz;
  Qm[5] = Qm[5] + wx;
  Qm[6] = Qm[6] + wy;
  Qm[7] = Qm[7] - wx;
}

// Convected strain (Γ, Ω) before subtracting the reference strains (Γ0, Ω0): the value part of
// evaluate_element's computation, with the same arithmetic.
Vec6 raw_strain(const ElementReference& ref, const Vec3& x1, const Vec3& x2, const Quat& R1, const Quat& R2) {
  const double z[6] = {0, 0, 0, 0, 0, 0};
  double phi[3], Qm[9];
  rotation_kernel<double>(ref, R1, R2, z, z, phi, Qm);
  const double iL = 1.0 / ref.L0;
  const Vec3 d0 = x2 - x1;
  Vec6 s;
  for (int k = 0; k < 3; ++k) {
    double g = 0;
    for (int j = 0; j < 3; ++j) g += Qm[3 * k + j] * d0(j);
    s(k) = g * iL;
    s(3 + k) = phi[k] * iL;
  }
  s(0) -= 1.0;
  return s;
}

// First-order kinematics at the current state (shared by the consistent residual without
// tangent and by the Petrov–Galerkin form): the strain S = (Γ, Ω) relative to the reference,
// B = ∂S/∂(x1, θ1, x2, θ2) w.r.t. the spatial increments, Q = Λ_rᵀ and ∂Q/∂θ_a (a over the six
// nodal rotation variables). One forward-mode pass over the 6 rotation variables.
struct Kinematics {
  Vec6 strain;
  Eigen::Matrix<double, 6, 12> B;
  Mat3 Q;
  std::array<Mat3, 6> dQ;
};

constexpr int kRotDof[6] = {3, 4, 5, 9, 10, 11};

void first_order_kinematics(const ElementReference& ref, const Vec3& x1, const Vec3& x2, const Quat& R1, const Quat& R2,
                            Kinematics& k) {
  using D1 = Dual<double, 6>;
  const double iL = 1.0 / ref.L0;
  const Vec3 d0 = x2 - x1;
  D1 pe[6], pd[6];
  for (int i = 0; i < 6; ++i) {
    pe[i] = D1(0.0);
    pe[i].d[i] = 1.0;
    pd[i] = D1(0.0);
  }
  D1 phi[3], Q[9];
  rotation_kernel<D1>(ref, R1, R2, pe, pd, phi, Q);
  auto& B = k.B;
  auto& strain = k.strain;
  B.setZero();
  for (int r = 0; r < 3; ++r) {
    double g = 0;
    for (int j = 0; j < 3; ++j) g += Q[3 * r + j].v * d0(j);
    strain(r) = g * iL;
    for (int j = 0; j < 3; ++j) {
      B(r, j) = -Q[3 * r + j].v * iL;
      B(r, 6 + j) = Q[3 * r + j].v * iL;
    }
    for (int a = 0; a < 6; ++a) {
      double ba = 0;
      for (int j = 0; j < 3; ++j) ba += Q[3 * r + j].d[a] * d0(j);
      B(r, kRotDof[a]) = ba * iL;
    }
    strain(3 + r) = phi[r].v * iL;
    for (int a = 0; a < 6; ++a) B(3 + r, kRotDof[a]) = phi[r].d[a] * iL;
  }
  strain(0) -= 1.0;
  strain.head<3>() -= ref.Gamma0;
  strain.tail<3>() -= ref.Omega0;
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j) {
      k.Q(r, j) = Q[3 * r + j].v;
      for (int a = 0; a < 6; ++a) k.dQ[a](r, j) = Q[3 * r + j].d[a];
    }
}

// Petrov–Galerkin residual of 4C's beam3r (Jelenić & Crisfield 1999) at the single Gauss point:
// the test functions of δx and δθ are both the Lagrange functions I_a (I_a = ½, I_a' = ∓1/L at
// the midpoint), so with n = Λ_r F, m = Λ_r M and d = x2 − x1 (∫ I_a x' ds = d/2)
//   r_x1 = −n,  r_θ1 = −m − ½ d×n,  r_x2 = n,  r_θ2 = m − ½ d×n.
// The consistent form differs only in the rotational test functions (Ĩ instead of I).
void petrov_galerkin_residual(const Kinematics& k, const Vec3& d, const Vec6& sig, Vec12& r) {
  const Vec3 n = k.Q.transpose() * sig.head<3>();
  const Vec3 m = k.Q.transpose() * sig.tail<3>();
  const Vec3 half_dxn = 0.5 * d.cross(n);
  r.segment<3>(0) = -n;
  r.segment<3>(3) = -m - half_dxn;
  r.segment<3>(6) = n;
  r.segment<3>(9) = m - half_dxn;
}

// Exact linearization of petrov_galerkin_residual w.r.t. (Δx, Δθ) (spatial increments):
//   Δn = Λ_r C_F B Δ + (∂Λ_r/∂θ) F,  Δm likewise with M,
//   Δ(d×n) = Δd×n + d×Δn = −[n]× Δd + [d]× Δn.
// Only first derivatives of the kinematics enter (no geometric term from second derivatives of
// the strains), and the result is not symmetric.
void petrov_galerkin_tangent(const Kinematics& k, const Vec3& d, const Vec6& sig, const Mat6& C, Mat12& K) {
  using Mat3x12 = Eigen::Matrix<double, 3, 12>;
  const Eigen::Matrix<double, 6, 12> CB = C * k.B;
  Mat3x12 Dn = k.Q.transpose() * CB.topRows<3>();
  Mat3x12 Dm = k.Q.transpose() * CB.bottomRows<3>();
  for (int a = 0; a < 6; ++a) {
    Dn.col(kRotDof[a]) += k.dQ[a].transpose() * sig.head<3>();
    Dm.col(kRotDof[a]) += k.dQ[a].transpose() * sig.tail<3>();
  }
  const Vec3 n = k.Q.transpose() * sig.head<3>();
  Mat3 dx, nx;  // [d]×, [n]×
  dx << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
  nx << 0, -n.z(), n.y(), n.z(), 0, -n.x(), -n.y(), n.x(), 0;
  Mat3x12 half_Ddxn = 0.5 * (dx * Dn);  // ½ Δ(d×n); Δd = Δx2 − Δx1
  half_Ddxn.middleCols<3>(0) += 0.5 * nx;
  half_Ddxn.middleCols<3>(6) -= 0.5 * nx;
  K.middleRows<3>(0) = -Dn;
  K.middleRows<3>(3) = -Dm - half_Ddxn;
  K.middleRows<3>(6) = Dn;
  K.middleRows<3>(9) = Dm - half_Ddxn;
}

ElementResult evaluate_petrov_galerkin(const Section& sec, const ElementReference& ref, const Vec3& x1, const Vec3& x2,
                                       const Quat& R1, const Quat& R2, const PlasticState& committed,
                                       bool with_tangent) {
  ElementResult out;
  Kinematics k;
  first_order_kinematics(ref, x1, x2, R1, R2, k);
  out.strain = k.strain;
  out.section = evaluate_section(sec, k.strain, committed);
  const Vec3 d = x2 - x1;
  petrov_galerkin_residual(k, d, out.section.stress, out.residual);
  if (with_tangent)
    petrov_galerkin_tangent(k, d, out.section.stress, out.section.tangent, out.tangent);
  else
    out.tangent.setZero();
  return out;
}

}  // namespace

Quat quat_exp(const Vec3& th) {
  const double a = th.norm();
  if (a < 1e-300) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(a, th / a));
}

Vec3 quat_log(const Quat& qin) {
  Quat q = qin.normalized();
  if (q.w() < 0) q.coeffs() *= -1.0;
  const Vec3 v = q.vec();
  const double nv = v.norm();
  if (nv < 1e-12) return 2.0 * v / q.w();
  return 2.0 * std::atan2(nv, q.w()) * v / nv;
}

Quat triad_from_tangent(const Vec3& t, const Vec3& up) {
  Vec3 e1 = t.normalized();
  Vec3 e2 = up - up.dot(e1) * e1;
  if (e2.norm() < 1e-8 * up.norm() || up.norm() == 0) {
    // pick any perpendicular
    Vec3 a = std::abs(e1.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
    e2 = a - a.dot(e1) * e1;
  }
  e2.normalize();
  Vec3 e3 = e1.cross(e2);
  Mat3 R;
  R.col(0) = e1;
  R.col(1) = e2;
  R.col(2) = e3;
  return Quat(R).normalized();
}

ElementReference make_element_reference(const Vec3& X1, const Vec3& X2, const Quat& O1, const Quat& O2) {
  ElementReference ref;
  ref.L0 = (X2 - X1).norm();
  ref.O1 = O1.normalized();
  ref.O2 = O2.normalized();
  Vec6 s = raw_strain(ref, X1, X2, Quat::Identity(), Quat::Identity());
  ref.Gamma0 = s.head<3>();
  ref.Omega0 = s.tail<3>();
  return ref;
}

Vec6 element_strain(const ElementReference& ref, const Vec3& x1, const Vec3& x2, const Quat& R1, const Quat& R2) {
  Vec6 s = raw_strain(ref, x1, x2, R1, R2);
  s.head<3>() -= ref.Gamma0;
  s.tail<3>() -= ref.Omega0;
  return s;
}

ElementResult evaluate_element(const Section& sec, const ElementReference& ref, const Vec3& x1, const Vec3& x2,
                               const Quat& R1, const Quat& R2, const PlasticState& committed, bool with_tangent,
                               ResidualForm form) {
  if (form == ResidualForm::petrov_galerkin)
    return evaluate_petrov_galerkin(sec, ref, x1, x2, R1, R2, committed, with_tangent);
  ElementResult out;
  if (!with_tangent) {  // residual only: first derivatives of the kinematics suffice
    Kinematics k;
    first_order_kinematics(ref, x1, x2, R1, R2, k);
    out.strain = k.strain;
    out.section = evaluate_section(sec, k.strain, committed);
    out.residual = ref.L0 * (k.B.transpose() * out.section.stress);
    out.tangent.setZero();
    return out;
  }
  // Strain S = (Γ, Ω) with Γ = Q (x2 − x1)/L − E1 − Γ0, Ω = φ/L − Ω0, where Q = Λ_rᵀ and φ
  // depend only on the rotations. Nested duals over the 6 rotation variables give Q, φ, their
  // first derivatives w.r.t. the variations (ε) and the increments (Δ), and the mixed second
  // derivatives; the position dependence is linear and added by hand.
  using D1 = Dual<double, 6>;
  using D2 = Dual<D1, 6>;
  const int* rdof = kRotDof;
  const double iL = 1.0 / ref.L0;
  const Vec3 d0 = x2 - x1;
  Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
  std::array<Mat12, 6> H;
  Vec6 strain;
  D2 pe[6], pd[6];
  for (int i = 0; i < 6; ++i) {
    pe[i] = D2(0.0);
    pe[i].d[i] = D1(1.0);
    pd[i] = D2(0.0);
    pd[i].v.d[i] = 1.0;
  }
  D2 phi[3], Q[9];
  rotation_kernel<D2>(ref, R1, R2, pe, pd, phi, Q);
  for (auto& h : H) h.setZero();
  for (int k = 0; k < 3; ++k) {
    // Γ_k
    double g = 0;
    for (int j = 0; j < 3; ++j) g += Q[3 * k + j].v.v * d0(j);
    strain(k) = g * iL;
    for (int j = 0; j < 3; ++j) {
      B(k, j) = -Q[3 * k + j].v.v * iL;
      B(k, 6 + j) = Q[3 * k + j].v.v * iL;
    }
    for (int a = 0; a < 6; ++a) {
      double ba = 0;
      for (int j = 0; j < 3; ++j) ba += Q[3 * k + j].d[a].v * d0(j);
      B(k, rdof[a]) = ba * iL;
      for (int b = 0; b < 6; ++b) {
        double hab = 0;
        for (int j = 0; j < 3; ++j) hab += Q[3 * k + j].d[a].d[b] * d0(j);
        H[k](rdof[a], rdof[b]) = hab * iL;
      }
      for (int j = 0; j < 3; ++j) {
        // ε_θa with Δ_x, and ε_x with Δ_θa
        H[k](rdof[a], j) = -Q[3 * k + j].d[a].v * iL;
        H[k](rdof[a], 6 + j) = Q[3 * k + j].d[a].v * iL;
        H[k](j, rdof[a]) = -Q[3 * k + j].v.d[a] * iL;
        H[k](6 + j, rdof[a]) = Q[3 * k + j].v.d[a] * iL;
      }
    }
    // Ω_k
    strain(3 + k) = phi[k].v.v * iL;
    for (int a = 0; a < 6; ++a) {
      B(3 + k, rdof[a]) = phi[k].d[a].v * iL;
      for (int b = 0; b < 6; ++b) H[3 + k](rdof[a], rdof[b]) = phi[k].d[a].d[b] * iL;
    }
  }
  strain(0) -= 1.0;
  strain.head<3>() -= ref.Gamma0;
  strain.tail<3>() -= ref.Omega0;
  out.strain = strain;
  out.section = evaluate_section(sec, strain, committed);
  const Vec6& sig = out.section.stress;
  out.residual = ref.L0 * (B.transpose() * sig);
  out.tangent = ref.L0 * (B.transpose() * out.section.tangent * B);
  for (int k = 0; k < 6; ++k) out.tangent += (ref.L0 * sig(k)) * H[k];
  return out;
}

}  // namespace angio::beam
