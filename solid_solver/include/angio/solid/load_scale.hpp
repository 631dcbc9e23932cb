// The force scale of a scene's loads, against which an absolute residual tolerance is judged.
// Units: mm, N, MPa.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "angio/solid/mesh.hpp"

namespace angio::solid {

// Euclidean norm (N) of the assembled nodal force vector of uniform pressures on surface sets of the
// reference configuration, each pair (surface name, pressure in MPa); the same face integral as the
// residual's follower pressure (face_pressure). It is the norm the Newton residual ||r|| is compared
// with: a residual tolerance near it accepts a step before the load has moved anything.
// A surface name the mesh does not have: std::invalid_argument.
double pressure_load_norm(const Mesh& mesh, const std::vector<std::pair<std::string, double>>& pressures);

}  // namespace angio::solid
