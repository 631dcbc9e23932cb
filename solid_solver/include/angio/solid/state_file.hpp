// Solid state files: the committed state of a run's parts, from which a later run continues (the
// next phase of a procedure, with the artery carried over and a new balloon; or the same scene
// resumed after a stop).
//
//   <run>/solid/state.h5   (HDF5, written by all ranks together through MPI-IO, each a contiguous
//                           block of every table, to state.h5.tmp and renamed: a reader never sees
//                           a half-written file, a crash keeps the last complete one; the file is
//                           the same whatever the number of ranks that wrote it)
//     attributes  format (1), time (s, the committed pseudo-time), step (committed steps of its run)
//     /parts/<part>/coordinates        [n,3]  reference coordinates of the part's nodes (ascending
//                                             node index of the mesh): checked against the new run's
//                                             mesh, so a state lands only on the mesh it came from
//     /parts/<part>/displacement       [n,3]  committed displacement (mm)
//     /parts/<part>/displacement_before [n,3] the commit before it, attribute before_time (s); only
//                                             with solid.newton.prediction: extrapolate
//     /parts/<part>/viscous_points     [k]    per element of the part (ascending element index): its
//                                             Gauss points with a viscous history (0: none)
//     /parts/<part>/viscous_Q, viscous_Sv [m,6] their committed Q and Sv (viscous.hpp), element after
//                                             element, Gauss points in the element rule's order
//
// Parts are the mesh's Block::part names ("balloon", "artery"). What is not in the file (a part not
// listed, the stent contact's last sample points, the Newton factorization) starts afresh.
#pragma once
#include <string>
#include <vector>

#include "angio/common/h5_io.hpp"
#include "angio/solid/model.hpp"

namespace angio::solid {

using StateFileError = h5::Error;

// What a state file holds of a part: the sizes of its tables. The rows stay in the file and are read
// in chunks where they are used (check_state, apply_state), so that no rank holds a whole part's
// state (a rank keeps the rows of the nodes it holds and of its elements only).
struct PartState {
  std::string name;
  long nodes = 0;     // rows of coordinates, displacement (and displacement_before)
  long elements = 0;  // rows of viscous_points
  long points = 0;    // rows of viscous_Q and viscous_Sv
};
struct StateFile {
  std::string path;
  double time = 0.0;
  int step = 0;
  bool has_before = false;
  double before_time = 0.0;
  std::vector<PartState> parts;
  const PartState* part(const std::string& name) const;
};

// Nodes (ascending) and elements (ascending) of the blocks whose part is `part`.
std::vector<int> part_nodes(const Mesh& mesh, const std::string& part);
std::vector<int> part_elements(const Mesh& mesh, const std::string& part);

// Collective: the committed state of every part of the model into `path`. No rank gathers it: each
// sends the rows of its owned nodes and its elements to the rank that writes their block of the file
// (file_blocks.hpp).
void write_state_file(SolidModel& model, const std::string& path, int step);
// Reads a state file's header and checks its tables (shapes, counts, every value finite) chunk by
// chunk (any rank, independently). Throws StateFileError naming the file.
StateFile read_state_file(const std::string& path);
// Checks that `parts` of the file fit `mesh` (same nodes at the same reference coordinates to
// 1e-9 mm, same Gauss points with history per element), reading the file in chunks. Throws
// StateFileError saying what differs.
void check_state(const StateFile& state, const Mesh& mesh, const std::vector<std::string>& parts,
                 const std::vector<LayerMaterial>& materials);
// Collective: the model continues from `parts` of the state at the state's time; nodes of other parts
// start undeformed, elements of other parts without viscous history. Each rank reads the file in
// chunks and keeps the rows of the nodes it holds and of its elements. check_state() first.
void apply_state(SolidModel& model, const StateFile& state, const std::vector<std::string>& parts);

}  // namespace angio::solid
