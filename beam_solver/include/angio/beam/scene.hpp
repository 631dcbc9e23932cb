// Reads the `stent:` section of a scene (see beam_solver/README.md for the schema) into a
// BeamModel. Every invalid input throws angio::scene::SceneError "file: key.path: expected …".
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "angio/beam/model.hpp"
#include "angio/beam/state_file.hpp"
#include "angio/beam/stent_generator.hpp"
#include "angio/scene/load_curve.hpp"
#include "angio/scene/node.hpp"
#include "angio/scene/output_settings.hpp"

namespace angio::beam {

struct BeamScene {
  std::string file;
  std::unique_ptr<BeamModel> model;
  scene::TimeSettings time;
  scene::OutputSettings output;
  // stent.initial_state: the committed stent of an earlier run (checked against this stent), applied
  // by the participant; time.start is its time.
  std::optional<BeamState> initial_state;
  bool generated_stent = false;
  std::optional<StentMesh> stent;
};

BeamScene load_beam_scene(const std::string& path);
BeamScene beam_scene_from(const scene::Node& root);

}  // namespace angio::beam
