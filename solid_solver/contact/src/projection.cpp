#include "angio/contact/projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace angio::contact {

const char* name(Location l) {
  switch (l) {
    case Location::Interior:
      return "interior";
    case Location::Edge:
      return "edge";
    case Location::Corner:
      return "corner";
  }
  return "?";
}

namespace {

double half_dist2(FaceKind k, const FaceX& X, const Vec2& xi, const Vec3& x) {
  ShapeN N;
  shape(k, xi, N);
  return 0.5 * (x - X * N).squaredNorm();
}

bool far_outside(FaceKind k, const Vec2& xi) {
  if (k == FaceKind::Quad4) return xi.lpNorm<Eigen::Infinity>() > 3.0;
  return xi[0] < -2.0 || xi[1] < -2.0 || xi[0] + xi[1] > 3.0;
}

struct EdgeMin {
  double f = std::numeric_limits<double>::infinity();
  double t = 0.0;
  int iterations = 0;
};

// Minimize f(t) = |x - x_s(A + t D)|^2 / 2 over t in [0, 1] (clamped Newton with backtracking).
EdgeMin edge_min(FaceKind k, const FaceX& X, const Vec3& x, const Vec2& A, const Vec2& D,
                 const ProjectionOptions& opt) {
  EdgeMin best;
  for (double t0 : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double f = half_dist2(k, X, A + t0 * D, x);
    if (f < best.f) {
      best.f = f;
      best.t = t0;
    }
  }
  double t = best.t, f = best.f;
  int it = 0;
  for (; it < opt.max_iter; ++it) {
    const FacePoint P = evaluate(k, X, A + t * D);
    const Vec3 r = x - P.x;
    const Vec3 st = P.a1 * D[0] + P.a2 * D[1];
    const Vec3 stt = P.a11 * D[0] * D[0] + 2.0 * P.a12 * D[0] * D[1] + P.a22 * D[1] * D[1];
    const double fp = -r.dot(st);
    double fpp = st.dot(st) - r.dot(stt);
    if (!(fpp > 1e-3 * st.dot(st))) fpp = st.dot(st);
    if (fpp <= 0) break;
    double dt = -fp / fpp;
    double tn = std::clamp(t + dt, 0.0, 1.0);
    double fn = half_dist2(k, X, A + tn * D, x);
    const bool small = std::abs(dt) < 1e-4;
    for (int ls = 0; ls < 30 && !small && fn > f && std::abs(tn - t) > opt.tol; ++ls) {
      tn = 0.5 * (t + tn);
      fn = half_dist2(k, X, A + tn * D, x);
    }
    const double step = tn - t;
    if (small || fn <= f) {
      t = tn;
      f = fn;
    }
    if (std::abs(step) < opt.tol) break;
  }
  best.t = t;
  best.f = f;
  best.iterations = it;
  return best;
}

}  // namespace

Projection project(FaceKind k, const FaceX& X, double normal_sign, const Vec3& x, const ProjectionOptions& opt) {
  Projection p;
  // Robust start: best of a few sample points.
  static const std::vector<Vec2> quad_starts = {Vec2(0, 0),      Vec2(-0.6, -0.6), Vec2(0, -0.6),
                                                Vec2(0.6, -0.6), Vec2(-0.6, 0),    Vec2(0.6, 0),
                                                Vec2(-0.6, 0.6), Vec2(0, 0.6),     Vec2(0.6, 0.6)};
  static const std::vector<Vec2> tri_starts = {Vec2(1.0 / 3, 1.0 / 3), Vec2(0.15, 0.15), Vec2(0.7, 0.15),
                                               Vec2(0.15, 0.7),        Vec2(0.45, 0.1),  Vec2(0.45, 0.45),
                                               Vec2(0.1, 0.45)};
  const auto& starts = k == FaceKind::Quad4 ? quad_starts : tri_starts;
  // Order the sample points by distance; run Newton from the best, and from the next ones if it fails.
  std::array<std::pair<double, int>, 9> order;
  const std::size_t nstart = starts.size();
  for (std::size_t i = 0; i < nstart; ++i) order[i] = {half_dist2(k, X, starts[i], x), static_cast<int>(i)};
  std::sort(order.begin(), order.begin() + nstart);

  Vec2 xi = starts[order[0].second];
  double f = order[0].first;
  bool converged = false, pd = false;
  double lam_min = 0.0;  // smallest eigenvalue of G^-1 H at the last iterate (1 - d kappa_max at a minimum)
  int it = 0;
  // Unconstrained Newton on f(xi) = |x - x_s(xi)|^2 / 2 (shifted Hessian if it is not positive definite).
  auto newton = [&](Vec2 xs, double fs) {
    xi = xs;
    f = fs;
    converged = pd = false;
    for (int i = 0; i < opt.max_iter; ++i, ++it) {
      const FacePoint P = evaluate(k, X, xi);
      const Vec3 r = x - P.x;
      const Vec2 grad(-r.dot(P.a1), -r.dot(P.a2));
      Eigen::Matrix2d G;
      G << P.a1.dot(P.a1), P.a1.dot(P.a2), P.a1.dot(P.a2), P.a2.dot(P.a2);
      Eigen::Matrix2d H = G;
      H(0, 0) -= r.dot(P.a11);
      H(1, 1) -= r.dot(P.a22);
      H(0, 1) -= r.dot(P.a12);
      H(1, 0) -= r.dot(P.a12);
      const double detG = G.determinant();
      if (!(detG > 0)) break;  // degenerate face
      pd = H(0, 0) > 0 && H.determinant() > 1e-12 * detG;
      {
        const double b = H(0, 0) * G(1, 1) + H(1, 1) * G(0, 0) - 2.0 * H(0, 1) * G(0, 1);
        lam_min = (b - std::sqrt(std::max(b * b - 4.0 * detG * H.determinant(), 0.0))) / (2.0 * detG);
      }
      Vec2 step;
      if (pd) {
        step = -H.inverse() * grad;
      } else {
        // Indefinite: shift the Hessian to positive definite (Levenberg-Marquardt), which follows directions of
        // negative curvature much faster than Gauss-Newton.
        const double tr = H.trace(), det = H.determinant();
        const double lmin = 0.5 * tr - std::sqrt(std::max(0.25 * tr * tr - det, 0.0));
        const double mu = -lmin + 0.05 * G.trace();
        step = -(H + mu * Eigen::Matrix2d::Identity()).inverse() * grad;
      }
      const double sn = step.lpNorm<Eigen::Infinity>();
      if (sn > 1.0) step /= sn;
      double lam = 1.0;
      double fn = half_dist2(k, X, xi + step, x);
      // Near the solution f changes below round-off: take full (quadratically convergent) Newton steps there;
      // backtrack only on large steps.
      const bool small = pd && sn < 1e-4;
      for (int ls = 0; ls < 30 && !small && fn > f && lam * step.norm() > opt.tol; ++ls) {
        lam *= 0.5;
        fn = half_dist2(k, X, xi + lam * step, x);
      }
      const double sl = lam * step.norm();
      if (small || fn <= f) {
        xi += lam * step;
        f = fn;
      }
      if (sl < opt.tol) {
        converged = true;
        break;
      }
      if (far_outside(k, xi)) break;
    }
    return converged && pd && inside(k, xi, opt.inside_tol);
  };
  const double h = (X.rowwise().maxCoeff() - X.rowwise().minCoeff()).norm();
  bool interior = newton(starts[order[0].second], order[0].first);
  // Several local minima exist only if x is farther from the face than its radius of curvature. If Newton
  // converged to a minimum (inside or outside the domain) where the Hessian is well conditioned with respect to the
  // metric (eigenvalues of G^-1 H, i.e. 1 - d kappa_i, >= trust_eigenvalue), that minimum is taken; otherwise Newton
  // is rerun from all sample points, the best interior minimum is kept and compared with the edge minima.
  const bool trusted = converged && pd && lam_min >= opt.trust_eigenvalue;
  if (opt.multi_start && !trusted) {
    Vec2 best_xi = xi;
    double best_f = interior ? f : std::numeric_limits<double>::infinity();
    for (std::size_t a = 1; a < nstart; ++a)
      if (newton(starts[order[a].second], order[a].first) && f < best_f) {
        best_f = f;
        best_xi = xi;
      }
    interior = best_f < std::numeric_limits<double>::infinity();
    if (interior) {
      xi = best_xi;
      f = best_f;
    }
  }

  p.iterations = it;
  if (interior) {
    p.location = Location::Interior;
    p.xi = xi;
  }
  // Constrained minimum on the boundary: minimize over each edge, keep the closest. Also after an interior solution
  // (check_edges): on a strongly curved face it can be a local minimum; the boundary then wins only if strictly closer.
  if (!interior || opt.check_edges) {
    const int nc = num_corners(k);
    double best = interior ? f - 1e-14 * h * h : std::numeric_limits<double>::infinity();
    for (int e = 0; e < nc; ++e) {
      const Vec2 A = corner_xi(k, e), B = corner_xi(k, (e + 1) % nc);
      const EdgeMin em = edge_min(k, X, x, A, B - A, opt);
      p.iterations += em.iterations;
      if (em.f < best) {
        best = em.f;
        if (em.t <= 0.0) {
          p.location = Location::Corner;
          p.index = e;
          p.xi = A;
          p.t = 0.0;
        } else if (em.t >= 1.0) {
          p.location = Location::Corner;
          p.index = (e + 1) % nc;
          p.xi = B;
          p.t = 0.0;
        } else {
          p.location = Location::Edge;
          p.index = e;
          p.t = em.t;
          p.xi = A + em.t * (B - A);
        }
      }
    }
  }

  const FacePoint P = evaluate(k, X, p.xi, normal_sign);
  const Vec3 r = x - P.x;
  p.s = P.x;
  p.n_face = P.n;
  p.distance = r.norm();
  if (p.location == Location::Interior || p.distance <= 1e-12 * h) {
    p.n = P.n;
    p.d = r.dot(p.n);
  } else {
    const double sg = r.dot(P.n) >= 0 ? 1.0 : -1.0;
    p.n = sg * r / p.distance;
    p.d = sg * p.distance;
  }
  p.valid = P.j > 0 && std::isfinite(p.distance);
  return p;
}

void linearize(FaceKind k, const FaceX& X, double normal_sign, const Vec3& x, const Projection& p, bool hessian,
               GapLinearization& out) {
  const int nn = num_nodes(k), m = 3 + 3 * nn;
  out.m = m;
  ShapeD dN;
  ShapeDD ddN;
  shape(k, p.xi, out.N, &dN, &ddN);
  const ShapeN& N = out.N;
  const FacePoint P = evaluate(k, X, p.xi, normal_sign);
  const Vec3 r = x - P.x;
  const Vec3& n = p.n;
  const Mat3 I = Mat3::Identity();

  // P: du -> dx - sum_b N_b dX_b
  Eigen::MatrixXd Pm = Eigen::MatrixXd::Zero(3, m);
  Pm.block<3, 3>(0, 0) = I;
  for (int b = 0; b < nn; ++b) Pm.block<3, 3>(0, 3 + 3 * b) = -N(b) * I;
  out.dd = n.transpose() * Pm;
  out.dxi = Eigen::MatrixXd::Zero(2, m);
  out.dn = Eigen::MatrixXd::Zero(3, m);

  const double h = (X.rowwise().maxCoeff() - X.rowwise().minCoeff()).norm();
  if (p.location == Location::Interior) {
    const Vec3 a[2] = {P.a1, P.a2};
    const Vec3 aa[2][2] = {{P.a11, P.a12}, {P.a12, P.a22}};
    Eigen::Matrix2d G, A, Hc;
    for (int al = 0; al < 2; ++al)
      for (int be = 0; be < 2; ++be) {
        G(al, be) = a[al].dot(a[be]);
        A(al, be) = G(al, be) - r.dot(aa[al][be]);
        Hc(al, be) = n.dot(aa[al][be]);
      }
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(2, m);
    for (int be = 0; be < 2; ++be) {
      B.block<1, 3>(be, 0) = a[be].transpose();
      for (int b = 0; b < nn; ++b) B.block<1, 3>(be, 3 + 3 * b) = -N(b) * a[be].transpose() + dN(b, be) * r.transpose();
    }
    out.dxi = A.inverse() * B;
    Eigen::Matrix<double, 3, 2> acov;
    acov << a[0], a[1];
    const Eigen::Matrix<double, 3, 2> acon = acov * G.inverse();
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(2, m);
    for (int al = 0; al < 2; ++al)
      for (int b = 0; b < nn; ++b) C.block<1, 3>(al, 3 + 3 * b) = dN(b, al) * n.transpose();
    out.dn = -acon * (C + Hc * out.dxi);
  } else if (std::abs(p.d) > 1e-12 * h) {
    const Mat3 T = I - n * n.transpose();
    if (p.location == Location::Edge) {
      const int nc = num_corners(k);
      const Vec2 D = corner_xi(k, (p.index + 1) % nc) - corner_xi(k, p.index);
      const Vec3 st = P.a1 * D[0] + P.a2 * D[1];
      const Vec3 stt = P.a11 * D[0] * D[0] + 2.0 * P.a12 * D[0] * D[1] + P.a22 * D[1] * D[1];
      double Ae = st.dot(st) - r.dot(stt);
      if (!(Ae > 1e-12 * st.dot(st))) Ae = st.dot(st);
      Eigen::RowVectorXd Bt = Eigen::RowVectorXd::Zero(m);
      Bt.segment<3>(0) = st.transpose();
      for (int b = 0; b < nn; ++b)
        Bt.segment<3>(3 + 3 * b) = -N(b) * st.transpose() + (dN(b, 0) * D[0] + dN(b, 1) * D[1]) * r.transpose();
      const Eigen::RowVectorXd dt = Bt / Ae;
      out.dxi = D * dt;
      out.dn = (T * Pm - st * dt) / p.d;
    } else {
      out.dn = T * Pm / p.d;
    }
  }

  if (hessian) {
    Eigen::MatrixXd Nd = Eigen::MatrixXd::Zero(m, 2);
    for (int b = 0; b < nn; ++b)
      for (int al = 0; al < 2; ++al) Nd.block<3, 1>(3 + 3 * b, al) = -dN(b, al) * n;
    out.hd = Pm.transpose() * out.dn + Nd * out.dxi;
  }
}

}  // namespace angio::contact
