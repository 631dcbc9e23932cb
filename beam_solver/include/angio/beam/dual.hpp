// Minimal forward-mode dual numbers (nestable) used to obtain the exact consistent tangent of the
// beam element by automatic differentiation: Dual<Dual<double,N>,N> yields first derivatives in
// two independent sets of variables and their mixed second derivatives.
#pragma once

#include <array>
#include <cmath>

namespace angio::beam {

template <class T, int N>
struct Dual {
  T v;
  std::array<T, N> d;
  Dual() = default;                                  // uninitialized (performance); use Dual(0.0) for a zero
  Dual(double c) : v(c) { d.fill(T(0.0)); }          // NOLINT: implicit constant
  explicit Dual(const T& value, bool) : v(value) {}  // derivatives set by the caller
};

inline double val(double x) { return x; }
template <class T, int N>
double val(const Dual<T, N>& a) {
  return val(a.v);
}

template <class T, int N>
Dual<T, N> operator+(const Dual<T, N>& a, const Dual<T, N>& b) {
  Dual<T, N> r(a.v + b.v, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] + b.d[i];
  return r;
}
template <class T, int N>
Dual<T, N> operator-(const Dual<T, N>& a, const Dual<T, N>& b) {
  Dual<T, N> r(a.v - b.v, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] - b.d[i];
  return r;
}
template <class T, int N>
Dual<T, N> operator-(const Dual<T, N>& a) {
  Dual<T, N> r(-a.v, true);
  for (int i = 0; i < N; ++i) r.d[i] = -a.d[i];
  return r;
}
template <class T, int N>
Dual<T, N> operator*(const Dual<T, N>& a, const Dual<T, N>& b) {
  Dual<T, N> r(a.v * b.v, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
  return r;
}
template <class T, int N>
Dual<T, N> operator*(const Dual<T, N>& a, double s) {
  Dual<T, N> r(a.v * s, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * s;
  return r;
}
template <class T, int N>
Dual<T, N> operator*(double s, const Dual<T, N>& a) {
  return a * s;
}
template <class T, int N>
Dual<T, N> operator+(const Dual<T, N>& a, double s) {
  Dual<T, N> r = a;
  r.v = r.v + s;
  return r;
}
template <class T, int N>
Dual<T, N> operator+(double s, const Dual<T, N>& a) {
  return a + s;
}
template <class T, int N>
Dual<T, N> operator-(const Dual<T, N>& a, double s) {
  return a + (-s);
}
template <class T, int N>
Dual<T, N> operator-(double s, const Dual<T, N>& a) {
  return (-a) + s;
}
template <class T, int N>
Dual<T, N> inv(const Dual<T, N>& a) {
  T iv = T(1.0) / a.v;
  T div = -(iv * iv);
  Dual<T, N> r(iv, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * div;
  return r;
}
template <class T, int N>
Dual<T, N> operator/(const Dual<T, N>& a, const Dual<T, N>& b) {
  return a * inv(b);
}
template <class T, int N>
Dual<T, N> operator/(const Dual<T, N>& a, double s) {
  return a * (1.0 / s);
}
template <class T, int N>
Dual<T, N> operator/(double s, const Dual<T, N>& a) {
  return inv(a) * s;
}

template <class T, int N>
Dual<T, N> sqrt(const Dual<T, N>& a) {
  using std::sqrt;
  T s = sqrt(a.v);
  T f = T(0.5) / s;
  Dual<T, N> r(s, true);
  for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * f;
  return r;
}
template <class T, int N>
Dual<T, N> atan2(const Dual<T, N>& y, const Dual<T, N>& x) {
  using std::atan2;
  T v = atan2(y.v, x.v);
  T den = T(1.0) / (x.v * x.v + y.v * y.v);
  Dual<T, N> r(v, true);
  for (int i = 0; i < N; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) * den;
  return r;
}

}  // namespace angio::beam
