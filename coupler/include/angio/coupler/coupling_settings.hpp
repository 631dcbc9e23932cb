// The scene's `coupling:` section: its keys, defaults and ranges are declared in
// core/scene/keys.yaml (docs/scene-keys.md); the scheme and the algorithm in docs/design.md.
#pragma once

#include <memory>
#include <string>

#include "angio/coupler/acceleration.hpp"
#include "angio/coupler/iqn_ils.hpp"
#include "angio/coupler/newton_krylov.hpp"
#include "angio/scene/node.hpp"

namespace angio::coupler {

struct CouplingSettings {
  std::string scheme = scene::keys::defaults::coupling_scheme;
  bool surface_compliance = scene::keys::defaults::coupling_surface_compliance;  // robin only
  std::string acceleration = scene::keys::defaults::coupling_acceleration;
  double initial_relaxation = scene::keys::defaults::coupling_initial_relaxation;
  double max_relaxation = 1.0;  // max(1, initial_relaxation) when not given
  IqnIlsOptions iqn;
  NewtonKrylovOptions newton_krylov;
  int max_iterations = scene::keys::defaults::coupling_max_iterations;
  double rel_tol = scene::keys::defaults::coupling_rel_tol;
  double abs_tol = scene::keys::defaults::coupling_abs_tol;
  bool strict = scene::keys::defaults::coupling_strict;
  double restart_growth = scene::keys::defaults::coupling_restart_growth;
  // > 0: a step whose coupling residual has not halved in this many iterations ends as at
  // max_iterations (rejected and cut when strict); 0: only max_iterations ends it.
  int stall_iterations = scene::keys::defaults::coupling_stall_iterations;
  std::string prediction = scene::keys::defaults::coupling_prediction;
  bool record = scene::keys::defaults::coupling_record;
  // Inexact solid solves: > 0 lets the solid solve coupling iteration k to an absolute residual of
  // inexact_solid x |w r_(k-1)| (N; r the coupling residual in N/mm, w the sample points' arc
  // lengths), iteration 0 to that factor times the previous step's first residual, so that its
  // equilibrium error stays this fraction of the interface error it is iterated against; the
  // accepted iterate's solid error is then at most that fraction of the residual before it.
  // 0: every solve to the solid's own tolerance.
  double inexact_solid = scene::keys::defaults::coupling_inexact_solid;
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
