// The `output:` section, shared by the solvers: how often fields are written and whether each
// solver keeps a state file to continue from (a later phase of a procedure, or a resumed run).
#pragma once
#include "angio/scene/node.hpp"

namespace angio::scene {

struct OutputSettings {
  int every = keys::defaults::output_every;  // fields at every `every`-th committed step (and the first)
  // A state file (<run>/<solver>/state.h5) rewritten at the steps with fields and at the end of the
  // run: the committed state a later run starts from (solid.initial_state, stent.initial_state).
  bool state = keys::defaults::output_state;
};
// Reads `output:` (absent: the defaults); unknown keys are refused.
OutputSettings output_settings(const Node& root);

}  // namespace angio::scene
