// Beam state files: the stent's committed state, from which a later run continues (the next phase
// of a procedure: the deployed stent keeps its shape and its plastic strains; or a resumed run).
//
//   <run>/beam/state.h5   (written to state.h5.tmp and renamed: never half-written)
//     attributes  format (1), time (s, committed pseudo-time), step (committed steps of its run)
//     /reference  [n,3]  reference node positions (checked against the new run's stent)
//     /position   [n,3]  committed node positions (mm)
//     /rotation   [n,4]  committed node rotations, unit quaternions (w, x, y, z)
//     /plastic    [E,4]  per element: plastic bending curvature (3) and its accumulated norm (material.hpp)
#pragma once
#include <string>
#include <vector>

#include "angio/beam/model.hpp"

namespace angio::beam {

struct BeamState {
  std::string path;
  double time = 0.0;
  int step = 0;
  std::vector<Vec3> X, x;
  std::vector<Quat> R;
  std::vector<PlasticState> plastic;
};

void write_beam_state(const BeamModel& model, const std::string& path, int step);
// Throws std::runtime_error naming the file.
BeamState read_beam_state(const std::string& path);
// Throws std::runtime_error saying what differs (node or element count, a reference position beyond 1e-9 mm).
void check_beam_state(const BeamState& state, const BeamModel& model);
void apply_beam_state(BeamModel& model, const BeamState& state);

}  // namespace angio::beam
