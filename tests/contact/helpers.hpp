// Test helpers: small meshes and finite-difference utilities for the contact tests.
#pragma once
#include <cmath>
#include <functional>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "angio/contact/contact.hpp"

namespace angio::contact::test {

struct Mesh {
  std::vector<Vec3> x;
  Surface surface;
};

// Flat quad4 grid in the plane z = z0, nodes (i*h, j*h), normal +z (counter-clockwise seen from +z).
inline Mesh flat_quads(int nx, int ny, double hx, double hy, double z0 = 0.0, double x0 = 0.0, double y0 = 0.0) {
  Mesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.x.emplace_back(x0 + i * hx, y0 + j * hy, z0);
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      Face f;
      f.kind = FaceKind::Quad4;
      f.nodes = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), 0, 0};
      m.surface.faces.push_back(f);
    }
  return m;
}

inline Vec3 cyl(double R, double th, double z) { return {R * std::cos(th), R * std::sin(th), z}; }

// Cylinder of radius R around the z axis, nt faces around (full circle if closed), nz along [0, L].
// quad4 or tri6 (each quad split in two; mid-edge nodes placed on the cylinder). Normal outward (+e_r).
inline Mesh cylinder(FaceKind kind, double R, double L, int nt, int nz, double th0 = 0.0, double th1 = 2 * M_PI) {
  Mesh m;
  const bool closed = std::abs(th1 - th0 - 2 * M_PI) < 1e-12;
  const int ntn = closed ? nt : nt + 1;
  const double dth = (th1 - th0) / nt, dz = L / nz;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i < ntn; ++i) m.x.push_back(cyl(R, th0 + i * dth, j * dz));
  auto id = [&](int i, int j) { return j * ntn + (i % ntn); };
  auto mid = [&](double ti, double zj) {
    m.x.push_back(cyl(R, th0 + ti * dth, zj * dz));
    return static_cast<int>(m.x.size()) - 1;
  };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nt; ++i) {
      Face f;
      if (kind == FaceKind::Quad4) {
        f.kind = FaceKind::Quad4;
        f.nodes = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), 0, 0};
        m.surface.faces.push_back(f);
      } else {
        f.kind = FaceKind::Tri6;
        // (i,j) -> (i+1,j) -> (i+1,j+1)
        f.nodes = {id(i, j),        id(i + 1, j),        id(i + 1, j + 1),
                   mid(i + 0.5, j), mid(i + 1, j + 0.5), mid(i + 0.5, j + 0.5)};
        m.surface.faces.push_back(f);
        // (i,j) -> (i+1,j+1) -> (i,j+1)
        f.nodes = {id(i, j),       id(i + 1, j + 1), id(i, j + 1), mid(i + 0.5, j + 0.5), mid(i + 0.5, j + 1),
                   mid(i, j + 0.5)};
        m.surface.faces.push_back(f);
      }
    }
  return m;
}

// Central finite-difference Jacobian of f: R^n -> R^k at u.
inline Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& u, double h) {
  const Eigen::VectorXd f0 = f(u);
  Eigen::MatrixXd J(f0.size(), u.size());
  for (int i = 0; i < u.size(); ++i) {
    Eigen::VectorXd up = u, um = u;
    up[i] += h;
    um[i] -= h;
    J.col(i) = (f(up) - f(um)) / (2 * h);
  }
  return J;
}

inline Eigen::VectorXd flatten(const FaceX& X) { return Eigen::Map<const Eigen::VectorXd>(X.data(), X.size()); }
inline FaceX unflatten(const Eigen::VectorXd& v) {
  FaceX X(3, v.size() / 3);
  for (int i = 0; i < X.cols(); ++i) X.col(i) = v.segment<3>(3 * i);
  return X;
}

// Relative max-norm difference.
inline double rel_diff(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  const double s = std::max({A.cwiseAbs().maxCoeff(), B.cwiseAbs().maxCoeff(), 1e-300});
  return (A - B).cwiseAbs().maxCoeff() / s;
}

// Brute-force closest point on a face by dense sampling followed by a local pattern search (independent of the
// Newton projection): returns the minimal distance.
inline double brute_distance(FaceKind k, const FaceX& X, const Vec3& x, Vec2* best_xi = nullptr) {
  auto dist = [&](const Vec2& xi) {
    ShapeN N;
    shape(k, xi, N);
    return (x - X * N).norm();
  };
  auto clampd = [&](Vec2 xi) {
    if (k == FaceKind::Quad4) return Vec2(xi.cwiseMax(-1.0).cwiseMin(1.0));
    xi = xi.cwiseMax(0.0);
    const double s = xi.sum();
    if (s > 1) xi /= s;
    return xi;
  };
  const int n = 200;
  Vec2 bx = Vec2::Zero();
  double bd = 1e300;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      Vec2 xi = k == FaceKind::Quad4 ? Vec2(-1 + 2.0 * i / n, -1 + 2.0 * j / n) : Vec2(double(i) / n, double(j) / n);
      if (k != FaceKind::Quad4 && i + j > n) continue;
      const double d = dist(xi);
      if (d < bd) {
        bd = d;
        bx = xi;
      }
    }
  double step = 2.0 / n;
  while (step > 1e-13) {
    bool improved = false;
    for (const Vec2& dir :
         {Vec2(1, 0), Vec2(-1, 0), Vec2(0, 1), Vec2(0, -1), Vec2(1, 1), Vec2(-1, -1), Vec2(1, -1), Vec2(-1, 1)}) {
      const Vec2 c = clampd(bx + step * dir);
      const double d = dist(c);
      if (d < bd) {
        bd = d;
        bx = c;
        improved = true;
      }
    }
    if (!improved) step *= 0.5;
  }
  if (best_xi) *best_xi = bx;
  return bd;
}

// A warped, distorted quad4 (non-planar: node 2 lifted) of size ~1 mm.
inline FaceX warped_quad() {
  FaceX X(3, 4);
  X.col(0) = Vec3(0.0, 0.0, 0.0);
  X.col(1) = Vec3(1.1, 0.1, 0.05);
  X.col(2) = Vec3(1.3, 0.9, 0.35);
  X.col(3) = Vec3(-0.1, 1.0, -0.1);
  return X;
}

// A tri6 on a cylinder of radius Rc (corners and mid-edge nodes on the cylinder), normal outward.
inline FaceX cylinder_tri6(double Rc = 1.0) {
  const double t0 = 0.0, t1 = 0.5, z0 = 0.0, z1 = 0.6;
  FaceX X(3, 6);
  X.col(0) = cyl(Rc, t0, z0);
  X.col(1) = cyl(Rc, t1, z0);
  X.col(2) = cyl(Rc, t1, z1);
  X.col(3) = cyl(Rc, 0.5 * (t0 + t1), z0);
  X.col(4) = cyl(Rc, t1, 0.5 * (z0 + z1));
  X.col(5) = cyl(Rc, 0.5 * (t0 + t1), 0.5 * (z0 + z1));
  return X;
}

// Sums per-face contact contributions into a dense residual (and tangent if K is given) over n nodes.
inline Eigen::VectorXd assemble_dense(const std::vector<NodalContribution>& contributions, int n, Eigen::MatrixXd* K) {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(3 * n);
  if (K) K->setZero(3 * n, 3 * n);
  for (const NodalContribution& c : contributions)
    for (Eigen::Index a = 0; a < c.r.size() / 3; ++a) {
      r.segment<3>(3 * c.nodes[a]) += c.r.segment<3>(3 * a);
      if (K)
        for (std::size_t b = 0; b < c.nodes.size(); ++b)
          K->block<3, 3>(3 * c.nodes[a], 3 * c.nodes[b]) += c.K.block<3, 3>(3 * a, 3 * b);
    }
  return r;
}

// Checks an assembly r(u) (K: its tangent if non-null; `energy`: set by each call to the penalty potential)
// by central differences with step 1e-6: K = dr/du and r = dPi/du, both to 1e-6 relative. r: the residual at u.
inline void expect_fd_consistent(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&, Eigen::MatrixXd*)>& assemble, const double& energy,
    const Eigen::VectorXd& u, Eigen::VectorXd& r) {
  Eigen::MatrixXd K;
  r = assemble(u, &K);
  ASSERT_GT(r.norm(), 0.0);
  const Eigen::MatrixXd Kfd = fd_jacobian([&](const Eigen::VectorXd& v) { return assemble(v, nullptr); }, u, 1e-6);
  EXPECT_LT(rel_diff(K, Kfd), 1e-6);
  const Eigen::MatrixXd rfd = fd_jacobian(
      [&](const Eigen::VectorXd& v) {
        assemble(v, nullptr);
        return Eigen::VectorXd::Constant(1, energy);
      },
      u, 1e-6);
  EXPECT_LT(rel_diff(r.transpose(), rfd), 1e-6);
}

}  // namespace angio::contact::test
