#include "angio/contact/face.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace angio::contact {

int num_nodes(FaceKind k) {
  switch (k) {
    case FaceKind::Quad4:
      return 4;
    case FaceKind::Tri3:
      return 3;
    case FaceKind::Tri6:
      return 6;
  }
  return 0;
}

int num_corners(FaceKind k) { return k == FaceKind::Quad4 ? 4 : 3; }

const char* name(FaceKind k) {
  switch (k) {
    case FaceKind::Quad4:
      return "quad4";
    case FaceKind::Tri3:
      return "tri3";
    case FaceKind::Tri6:
      return "tri6";
  }
  return "?";
}

void shape(FaceKind k, const Vec2& xi, ShapeN& N, ShapeD* dN, ShapeDD* ddN) {
  const int n = num_nodes(k);
  N.resize(n);
  if (dN) dN->resize(n, 2);
  if (ddN) ddN->setZero(n, 3);
  if (k == FaceKind::Quad4) {
    static const int s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int a = 0; a < 4; ++a) {
      N(a) = 0.25 * (1 + s[a][0] * xi[0]) * (1 + s[a][1] * xi[1]);
      if (dN) {
        (*dN)(a, 0) = 0.25 * s[a][0] * (1 + s[a][1] * xi[1]);
        (*dN)(a, 1) = 0.25 * (1 + s[a][0] * xi[0]) * s[a][1];
      }
      if (ddN) (*ddN)(a, 2) = 0.25 * s[a][0] * s[a][1];
    }
    return;
  }
  const double L[3] = {1 - xi[0] - xi[1], xi[0], xi[1]};
  static const double dL[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  if (k == FaceKind::Tri3) {
    for (int a = 0; a < 3; ++a) {
      N(a) = L[a];
      if (dN) {
        (*dN)(a, 0) = dL[a][0];
        (*dN)(a, 1) = dL[a][1];
      }
    }
    return;
  }
  // tri6
  static const int e[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  static const int pairs[3][2] = {{0, 0}, {1, 1}, {0, 1}};  // (xi,xi), (eta,eta), (xi,eta)
  for (int a = 0; a < 3; ++a) {
    N(a) = L[a] * (2 * L[a] - 1);
    if (dN)
      for (int j = 0; j < 2; ++j) (*dN)(a, j) = (4 * L[a] - 1) * dL[a][j];
    if (ddN)
      for (int c = 0; c < 3; ++c) (*ddN)(a, c) = 4 * dL[a][pairs[c][0]] * dL[a][pairs[c][1]];
  }
  for (int m = 0; m < 3; ++m) {
    const int p = e[m][0], q = e[m][1];
    N(3 + m) = 4 * L[p] * L[q];
    if (dN)
      for (int j = 0; j < 2; ++j) (*dN)(3 + m, j) = 4 * (dL[p][j] * L[q] + L[p] * dL[q][j]);
    if (ddN)
      for (int c = 0; c < 3; ++c) {
        const int i = pairs[c][0], j = pairs[c][1];
        (*ddN)(3 + m, c) = 4 * (dL[p][i] * dL[q][j] + dL[p][j] * dL[q][i]);
      }
  }
}

Vec2 corner_xi(FaceKind k, int c) {
  if (k == FaceKind::Quad4) {
    static const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    return {s[c][0], s[c][1]};
  }
  static const double t[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  return {t[c][0], t[c][1]};
}

Vec2 center_xi(FaceKind k) { return k == FaceKind::Quad4 ? Vec2(0, 0) : Vec2(1.0 / 3, 1.0 / 3); }

bool inside(FaceKind k, const Vec2& xi, double tol) {
  if (k == FaceKind::Quad4) return std::abs(xi[0]) <= 1 + tol && std::abs(xi[1]) <= 1 + tol;
  return xi[0] >= -tol && xi[1] >= -tol && xi[0] + xi[1] <= 1 + tol;
}

FaceX gather(const Face& f, std::span<const Vec3> coords) {
  const int n = f.nn();
  FaceX X(3, n);
  for (int a = 0; a < n; ++a) {
    const int id = f.nodes[a];
    if (id < 0 || static_cast<std::size_t>(id) >= coords.size())
      throw std::out_of_range("angio::contact::gather: face node id out of range");
    X.col(a) = coords[id];
  }
  return X;
}

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
  return S;
}

FacePoint evaluate(FaceKind k, const FaceX& X, const Vec2& xi, double normal_sign) {
  ShapeN N;
  ShapeD dN;
  ShapeDD ddN;
  shape(k, xi, N, &dN, &ddN);
  FacePoint p;
  p.x = X * N;
  p.a1 = X * dN.col(0);
  p.a2 = X * dN.col(1);
  p.a11 = X * ddN.col(0);
  p.a22 = X * ddN.col(1);
  p.a12 = X * ddN.col(2);
  const Vec3 c = p.a1.cross(p.a2);
  p.j = c.norm();
  p.n = p.j > 0 ? Vec3(normal_sign * c / p.j) : Vec3::Zero();
  return p;
}

QuadratureRule face_rule(FaceKind k, int degree) {
  QuadratureRule r;
  if (k == FaceKind::Quad4) {
    const int n = std::clamp((degree + 2) / 2, 1, 4);
    static const std::vector<std::vector<double>> pts = {
        {0.0},
        {-0.5773502691896257645, 0.5773502691896257645},
        {-0.7745966692414833770, 0.0, 0.7745966692414833770},
        {-0.8611363115940525752, -0.3399810435848562648, 0.3399810435848562648, 0.8611363115940525752}};
    static const std::vector<std::vector<double>> wts = {
        {2.0},
        {1.0, 1.0},
        {5.0 / 9, 8.0 / 9, 5.0 / 9},
        {0.3478548451374538574, 0.6521451548625461426, 0.6521451548625461426, 0.3478548451374538574}};
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        r.xi.emplace_back(pts[n - 1][i], pts[n - 1][j]);
        r.w.push_back(wts[n - 1][i] * wts[n - 1][j]);
      }
    return r;
  }
  if (degree <= 1) {
    r.xi = {Vec2(1.0 / 3, 1.0 / 3)};
    r.w = {0.5};
  } else if (degree == 2) {
    r.xi = {Vec2(1.0 / 6, 1.0 / 6), Vec2(2.0 / 3, 1.0 / 6), Vec2(1.0 / 6, 2.0 / 3)};
    r.w = {1.0 / 6, 1.0 / 6, 1.0 / 6};
  } else {
    const double a1 = 0.445948490915965, b1 = 0.108103018168070, w1 = 0.223381589678011 / 2;
    const double a2 = 0.091576213509771, b2 = 0.816847572980459, w2 = 0.109951743655322 / 2;
    r.xi = {Vec2(a1, a1), Vec2(b1, a1), Vec2(a1, b1), Vec2(a2, a2), Vec2(b2, a2), Vec2(a2, b2)};
    r.w = {w1, w1, w1, w2, w2, w2};
  }
  return r;
}

Aabb face_box(FaceKind k, const FaceX& X) {
  Aabb b;
  for (int c = 0; c < num_corners(k); ++c) b.extend(Vec3(X.col(c)));
  if (k == FaceKind::Quad4) b.extend(Vec3(X.col(3)));
  if (k == FaceKind::Tri6) {
    static const int e[3][2] = {{0, 1}, {1, 2}, {2, 0}};
    for (int m = 0; m < 3; ++m) {
      const Vec3 ctrl = 2.0 * X.col(3 + m) - 0.5 * (X.col(e[m][0]) + X.col(e[m][1]));
      b.extend(ctrl);
      b.extend(Vec3(X.col(3 + m)));
    }
  }
  return b;
}

}  // namespace angio::contact
