// Parallel HDF5 + XDMF field output of the solid model (one file for the whole run).
//
//   <dir>/solid.h5
//     /mesh/coordinates            [N,3]  reference coordinates (solver node numbering)
//     /mesh/original_node_id       [N]    node index in the input mesh
//     /mesh/<type>/connectivity    [E,n]  (tet10 in VTK/XDMF edge order)
//     /mesh/<type>/block_id        [E]    block (layer) index, see summary.json "blocks"
//     /mesh/<type>/original_element_id [E]
//     /mesh/<type>/frame_circumferential, frame_axial, frame_radial [E,3]  if the mesh has fiber
//                                  frames (Mesh::frames): the element's local material frame
//     /mesh/<type>/fiber_<k>       [E,3]  with the frames: direction a0 of fiber family k = 1, 2, ...
//                                         of the element's material (cos φ e_c ± sin φ e_a, zero if
//                                         the material has fewer families)
//     /steps/<k>                   attribute "time" (pseudo-time, s)
//     /steps/<k>/displacement      [N,3]  nodal
//     /steps/<k>/<type>/stress_p1      [E]   first principal Cauchy stress (MPa), per element:
//                                              eigenvalue of the Gauss-point averaged Cauchy tensor
//     /steps/<k>/<type>/stress_p1_dir  [E,3] its unit eigenvector
//     /steps/<k>/<name>            [N]    extra nodal scalars, e.g. contact_pressure (MPa): |contact
//                                         force| / lumped nodal area on the endothelium
//     /steps/<k>/stress_p1_nodal_<layer>  [N]  recovered nodal first principal Cauchy stress (MPa) of
//                                         block (layer) <layer>, one field per block of the mesh
//                                         (Mesh::blocks names, characters other than [A-Za-z0-9_-]
//                                         replaced by '_', "_<block id>" appended to a repeated name):
//                                         eigenvalue of the L2 projection of the Gauss-point Cauchy
//                                         tensor onto the nodes of that layer alone (stress_recovery.hpp),
//                                         so an interface node has one value in each of its layers' fields.
//                                         NaN at the nodes outside the layer: in ParaView colour the field
//                                         on that layer's cells (Threshold on block_id); cells of other
//                                         layers show the NaN colour.
//   <dir>/solid.xdmf  (rewritten after every step; open in ParaView with the Xdmf3 reader; every
//                      step's grids carry the static /mesh cell data as attributes too)
#pragma once
#include <hdf5.h>

#include <string>
#include <vector>

#include "angio/solid/model.hpp"

namespace angio::solid {

class FieldWriter {
 public:
  FieldWriter(const SolidModel& model, const std::string& dir);  // collective
  ~FieldWriter();
  // Collective. p1/dir: per local element (model.local_elements() order), from element_stress().
  // nodal: extra nodal scalar fields given for this rank's owned nodes (new numbering, entry i for
  // node owned_node_begin() + i), e.g. the recovered stresses (nodal_stress_field_name), the contact
  // pressure.
  void write_step(int step, double time, const std::vector<double>& p1, const std::vector<Vec3d>& dir,
                  const std::vector<std::pair<std::string, const std::vector<double>*>>& nodal = {});
  void close();

 private:
  void write_xdmf_();
  const SolidModel& model_;
  std::string dir_;
  hid_t file_ = -1;
  struct TypeInfo {
    ElemType type;
    long total = 0, offset = 0;
    std::vector<int> local;  // indices into model.local_elements()
  };
  std::vector<TypeInfo> types_;
  void write_cell_vectors_(const TypeInfo& ti, const std::string& base);  // collective
  std::vector<std::string> cell_vectors_;  // static per-element vectors under /mesh/<type>/ (frames, fibers)
  struct StepInfo {
    int step;
    double time;
    std::vector<std::string> nodal;  // names of the extra nodal fields of this step
  };
  std::vector<StepInfo> steps_;
};

// Names of the recovered nodal stress fields, one per block: "stress_p1_nodal_<block name>" with the
// name reduced to [A-Za-z0-9_-] (others become '_') and "_<block id>" appended where that makes two
// names equal.
std::vector<std::string> nodal_stress_field_names(const Mesh& mesh);

// Creates a directory and its parents (like mkdir -p); throws on failure.
void make_directories(const std::string& dir);

}  // namespace angio::solid
