// Reading a centerline from a scene, one key shape for every part (stent.generator.centerline,
// balloon.mesh.centerline, artery.mesh.centerline), so one centerline file serves all of them:
//   centerline: {file: centerlines/x.txt}          (path relative to the scene file)
//   centerline: {points: [[x, y, z], ...]}
//   centerline: [[x, y, z], ...]                   (short form of points)
// Errors name the scene file, the key path and what was expected (scene::SceneError).
#pragma once

#include "angio/geometry/centerline.hpp"
#include "angio/scene/node.hpp"

namespace angio::geometry {

Centerline centerline_from_scene(const scene::Node& node);

}  // namespace angio::geometry
