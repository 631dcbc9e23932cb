// Viscous branch of the artery's media and intima (paper appendix B, eqs. B.5–B.8): a generalized
// Maxwell element in parallel with the hyperelastic ground stress S∞,
//     Q̇ + Q/τ = β Ṡv,    S = S∞ + Q,
// τ the relaxation time (s), β the ratio of the viscoelastic to the hyperelastic branch
// (Holzapfel, Nonlinear Solid Mechanics (2000) §6.10; Simo, CMAME 60 (1987)). Sv is the part of S∞
// the branch acts on (ViscousBranch::acts_on, materials.hpp): the isotropic Neo-Hooke stress
// (default, as 4C's VISCO_GenMax) or all of S∞ (matrix and fibers).
//
// Time integration: over a step [t_n, t_n+1] Sv is taken linear in time, for which the convolution
// solution of the ODE is exact:
//     Q_n+1 = e^(−ξ) Q_n + β g(ξ) (Sv_n+1 − Sv_n),   ξ = Δt/τ,  g(ξ) = (1 − e^(−ξ))/ξ,
// (g → 1 as Δt → 0: the instantaneous response Q jumps by β ΔSv; held strain relaxes as e^(−t/τ)).
// This is the midpoint scheme of Simo–Hughes (1998, eq. 10.3.14) with e^(−ξ/2) replaced by its exact
// counterpart for a piecewise-linear history, so a constant-rate ramp and a relaxation are
// reproduced to round-off (tests/solid/test_viscous.cpp). Consistent tangent:
//     dS/dE = dS∞/dE + β g(ξ) dSv/dE.
// Pure kernel: the history (Q_n, Sv_n per Gauss point) is owned by SolidModel and committed per step.
#pragma once
#include "angio/solid/materials.hpp"

namespace angio::solid {

// g(ξ) = (1 − e^(−ξ))/ξ, evaluated without cancellation (g(0) = 1).
double viscous_rate_factor(double xi);

// Q_n+1 from the committed Q_n, S∞_n and the current S∞ (Voigt stress vectors) over the step dt ≥ 0.
// tangent_factor (optional) receives 1 + β g(ξ).
Vec6 viscous_update(const ViscousBranch& v, double dt, const Vec6& Q_n, const Vec6& S_inf_n, const Vec6& S_inf,
                    double* tangent_factor = nullptr);

// Stress S = S∞ + Q and tangent D = dS∞/dE + β g dSv/dE (D may be null) of a layer with a viscous
// branch at one material point: the Neo-Hooke matrix m and the resolved fibers at C, the branch v
// over the step dt from the committed Q_n and Sv_n. Returns the new Q and Sv (the part of S∞ the
// branch acts on) for the history. No allocation.
void viscous_stress_tangent(const NeoHooke& m, const std::vector<FiberFamily>& fibers, const ViscousBranch& v,
                            double dt, const Vec6& Q_n, const Vec6& Sv_n, const Mat3& C, Mat3& S, Mat6* D, Vec6& Q,
                            Vec6& Sv);

// Committed history of one element's Gauss points (arrays of length = number of Gauss points), and
// where to store the updated history (commit) if Q_out/S_out are set.
struct ViscousHistory {
  ViscousBranch branch;
  double dt = 0.0;
  const Vec6* Q_n = nullptr;
  const Vec6* S_n = nullptr;  // Sv_n: the committed part of S∞ the branch acts on
  Vec6* Q_out = nullptr;
  Vec6* S_out = nullptr;
};

}  // namespace angio::solid
