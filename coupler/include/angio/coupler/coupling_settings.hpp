// The scene's `coupling:` section (docs/design.md §5).
//   coupling:
//     scheme: dirichlet-neumann   # dirichlet-neumann | robin (interface_scheme.hpp)
//     acceleration: aitken        # aitken | iqn-ils | constant
//     initial_relaxation: 0.5     # ω_0
//     max_relaxation: 1.0         # cap on |ω| (aitken)
//     iqn: {reused_steps: 8, max_columns: 100, filter: 1.0e-2, stagnation: 1.0e-3}   # iqn-ils model (iqn_ils.hpp)
//     max_iterations: 50
//     rel_tol: 1.0e-4             # ||r|| <= rel_tol·||q~|| + abs_tol·sqrt(len)
//     abs_tol: 1.0e-6             # N/mm
//     strict: true                # hitting max_iterations rejects the step (false: accept + warn)
//     restart_growth: 0           # > 1: restart the acceleration (drop its model) when the residual
//                                 # exceeds restart_growth × the smallest of the step (0: never)
//     prediction: extrapolate     # constant | extrapolate: first iterate of a step
//     record: false               # record every exchange into <run-dir>/exchanges.angiorec
#pragma once

#include <memory>
#include <string>

#include "angio/coupler/acceleration.hpp"
#include "angio/coupler/iqn_ils.hpp"
#include "angio/scene/node.hpp"

namespace angio::coupler {

struct CouplingSettings {
  std::string scheme = "dirichlet-neumann";
  std::string acceleration = "aitken";
  double initial_relaxation = 0.5;
  double max_relaxation = 1.0;
  IqnIlsOptions iqn;
  int max_iterations = 50;
  double rel_tol = 1e-4;
  double abs_tol = 1e-6;
  bool strict = true;
  double restart_growth = 0.0;
  std::string prediction = "extrapolate";
  bool record = false;
  // Inexact solid solves: > 0 lets the solid solve coupling iteration k to an absolute residual of
  // inexact_solid x |w r_(k-1)| (N; r the coupling residual in N/mm, w the sample points' arc
  // lengths), iteration 0 to that factor times the previous step's first residual, so that its
  // equilibrium error stays this fraction of the interface error it is iterated against; the
  // accepted iterate's solid error is then at most that fraction of the residual before it.
  // 0: every solve to the solid's own tolerance.
  double inexact_solid = 0.0;
  // The run continues from state files (stent.initial_state or solid.initial_state given): before the
  // first step the interface state (the contact planes or loads of the committed state) is recomputed
  // from the participants, as the accepted state of the step before (coupling_loop.hpp). Derived
  // from the scene, not a key of `coupling:`.
  bool synchronize = false;
};

CouplingSettings coupling_settings(const scene::Node& root);
// The settings as one JSON object under the scene's key names (`coupler --print-settings`): the
// defaults declared above, read by scripts instead of copying them.
std::string settings_json(const CouplingSettings& s);
std::unique_ptr<Acceleration> make_acceleration(const CouplingSettings& s);

}  // namespace angio::coupler
