// In-process participants with an analytic coupled solution, for testing the coupling loop
// without processes: every sample point is a radial spring (stiffness kb per unit length) on the
// beam side, pushed by a rigid wall on the solid side that sits at radius s(t) and acts by penalty
// (eps): q~ = eps·max(s − x − R, 0) outward. Coupled fixed point, for contact:
//   q = eps (s − x0 − R − q/kb)  ⇒  q* = eps (s − x0 − R) / (1 + eps/kb).
// Gauss–Seidel without relaxation amplifies errors by −eps/kb: it diverges for eps > kb.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"

namespace angio::test {

using participant::Vec3;

struct SpringBeam : participant::BeamParticipant {
  int n = 4;
  double kb = 1.0, x0 = 1.0, R = 0.05;
  std::vector<double> x, x_committed;
  int fail_at_step = -1;  // Newton "fails" at this step once (tests step cutting)
  double delay = 0.0;     // s of sleep per solve (tests interruption of a running job)
  int step = 0, accepted = 0, rejected = 0;
  bool failed_once = false;

  explicit SpringBeam(int points = 4) : n(points), x(n, x0), x_committed(n, x0) {}
  participant::SamplePoints sample_points() const override {
    participant::SamplePoints p;
    for (int i = 0; i < n; ++i) {
      p.x.push_back({x[i], 0.0, 0.1 * i});
      p.w.push_back(0.1);
      p.radius.push_back(R);
    }
    return p;
  }
  void begin_step(int s, double) override { step = s; }
  participant::SolveStats solve(const std::vector<Vec3>& q) override {
    participant::SolveStats st;
    if (delay > 0) std::this_thread::sleep_for(std::chrono::duration<double>(delay));
    if (step == fail_at_step && !failed_once) {
      failed_once = true;
      st.converged = false;
      st.message = "injected failure";
      return st;
    }
    for (int i = 0; i < n; ++i) x[i] = x0 + q[i][0] / kb;
    st.converged = true;
    st.iterations = 1;
    return st;
  }
  // Robin mode: kb (x − x0) = c + plane load, with the plane law of plane_penalty.hpp along x
  // (normal ±e_x), solved in closed form for the active and the inactive branch.
  std::vector<double> plane_eps;  // penalty of point 0's plane at every robin solve (0: none)
  participant::SolveStats solve_with_planes(const std::vector<Vec3>& c, const participant::ContactPlanes& p) override {
    plane_eps.push_back(p.eps.empty() ? 0.0 : p.eps[0]);
    participant::SolveStats st = solve(c);
    for (int i = 0; i < n; ++i) {
      if (!(p.eps[i] > 0.0)) continue;
      const double nx = p.n[i][0], S = p.s[i][0], e = p.eps[i];
      // q = −e·(nx (x − S) − R)·nx for nx (x − S) − R < 0; nx = ±1
      const double x_act = (kb * x0 + c[i][0] + e * (S + nx * R)) / (kb + e);
      if (nx * (x_act - S) - R < 0.0) x[i] = x_act;
    }
    return st;
  }
  void end_step(bool accept) override {
    if (accept) {
      x_committed = x;
      ++accepted;
    } else {
      x = x_committed;
      ++rejected;
    }
  }
  void finish() override {}
};

struct WallSolid : participant::SolidParticipant {
  double eps = 10.0;
  double s_max = 1.5;  // wall radius at t = 1 (linear ramp s = x0 + (s_max − x0)·t)
  double x0 = 1.0;
  double s = 1.0;
  // Optional: the wall on springs, point i's surface giving way by q_i / kw_i (kw per unit length):
  // the contact is the series spring of penalty and surface, eps' = eps kw / (eps + kw), so
  // q~_i = eps' max(s − x_i − R, 0) and the coupled fixed point is q*_i = eps'_i (s − x0 − R) /
  // (1 + eps'_i / kb). The planes sit on the displaced surface. Empty: a rigid wall.
  std::vector<double> kw;
  double eps_series(std::size_t i) const { return kw.empty() ? eps : eps * kw[i] / (eps + kw[i]); }
  void begin_step(int, double t) override { s = x0 + (s_max - x0) * t; }
  std::vector<double> tolerances;  // of every solve request (the wall is solved exactly anyway)
  participant::SolveStats solve(const participant::SamplePoints& p, participant::ContactReply& reply,
                                double tolerance) override {
    tolerances.push_back(tolerance);
    reply = {};
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double g = s - p.x[i][0] - p.radius[i];
      const double q = eps_series(i) * std::max(g, 0.0);
      const double surface = kw.empty() ? s : s - q / kw[i];
      reply.line_loads.push_back({q, 0.0, 0.0});
      // robin data: the wall as a plane with normal +e_x toward the beam; the law
      // −eps·((x − S) − R) with S = surface − 2R equals eps·(surface − x − R) = q above.
      reply.surface_points.push_back({surface - 2.0 * p.radius[i], p.x[i][1], p.x[i][2]});
      reply.normals.push_back({1.0, 0.0, 0.0});
      reply.penalty.push_back(eps);
      reply.total_force[0] += p.w[i] * q;
      if (g > 0) ++reply.n_active;
    }
    participant::SolveStats st;
    st.converged = true;
    return st;
  }
  void end_step(bool) override {}
  void finish() override {}
};

}  // namespace angio::test
