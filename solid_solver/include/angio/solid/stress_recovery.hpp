// Recovered nodal stress per block (layer) of a SolidModel: the L2 projection of the Gauss-point
// Cauchy stress tensor onto the nodal interpolation of each block separately (element kernel:
// recovery_kernels.hpp), so that a node on a layer interface carries one tensor per layer, never an
// average across the interface. The element average (SolidModel::element_stress) sits half an
// element inside the wall; the projection extrapolates a stress gradient to the surface nodes (a
// linear field exactly, in affine elements), which is where the peak of a lumen-side layer lies.
//
// Distribution (as the model's): the unknowns (node, block) are interlaced, global row
// nb·p + b for the node's index p in the model's new numbering and block b of nb, so that every
// rank owns the rows of its owned nodes [owned_node_begin, owned_node_end) and needs no map; a
// (node, block) pair without an element of that block is an identity row (absent, has() false).
// Each rank adds the contributions of its own elements (PETSc sends those to rows of other ranks'
// nodes). No array of the whole mesh's size is allocated; the results are per owned node.
//
//   consistent (default): M σ = b solved by CG + Jacobi per Voigt component, relative tolerance
//                         1e-12, warm-started from the previous call. M is that of the reference
//                         configuration: assembled and set up once.
//   lumped:               σ_a = b_a / Σ_b M_ab. Cheaper, but it only averages the Gauss-point values
//                         near a node (no extrapolation to the surface), and it is refused for tet10
//                         (vertex row sums ∫ N_a dV < 0).
#pragma once
#include <petscksp.h>

#include <array>
#include <vector>

#include "angio/solid/model.hpp"

namespace angio::solid {

class StressRecovery {
 public:
  enum class Mass { consistent, lumped };
  // Collective. Throws std::runtime_error for a lumped mass with a non-positive row sum.
  explicit StressRecovery(const SolidModel& model, Mass mass = Mass::consistent);
  ~StressRecovery();
  StressRecovery(const StressRecovery&) = delete;
  StressRecovery& operator=(const StressRecovery&) = delete;

  // Collective. gauss: the Gauss-point Cauchy tensors of model.local_elements()
  // (SolidModel::element_stress(..., &gauss)). Returns false if a CG solve did not converge (the
  // values are then those of its last iterate).
  bool recover(const std::vector<Mat3>& gauss);

  int num_blocks() const { return nb_; }
  int num_owned() const { return nloc_; }  // owned nodes; owned node i has the new index owned_node_begin() + i
  // Owned node i, block b (after recover()):
  bool has(int i, int b) const { return weight_[size_t(i) * nb_ + b] > 0.0; }  // the node belongs to block b
  Mat3 stress(int i, int b) const;                                             // recovered Cauchy tensor (MPa)
  double p1(int i, int b) const { return p1_[size_t(i) * nb_ + b]; }           // its first principal value; NaN if !has
  // Share of the block's reference volume at the node: Σ over its elements of the block V_e / n_e
  // (positive; the weight of the nodal percentiles).
  double weight(int i, int b) const { return weight_[size_t(i) * nb_ + b]; }
  // p1 of block b for every owned node, NaN at nodes outside the block (the output field).
  std::vector<double> p1_field(int b) const;

  double last_seconds() const { return seconds_; }     // wall time of the last recover() on this rank
  int last_iterations() const { return iterations_; }  // CG iterations of the last recover() (6 solves)

 private:
  const SolidModel& model_;
  Mass mass_;
  int nb_ = 0, nloc_ = 0;
  std::vector<size_t> gauss_offset_;  // per local element: its first entry in the gauss vector
  // The right-hand side is linear in the Gauss-point stresses and the mesh is the reference one: per
  // local element the constant matrix B_e (n × n_gauss, column-major) with b_e = B_e S_e, S_e the
  // element's Gauss-point stresses as Voigt rows, and the element's rows of the system; both computed
  // once in the constructor, so a step does no quadrature.
  std::vector<double> load_;
  std::vector<size_t> load_offset_;
  std::vector<PetscInt> rows_;  // per local element its nn() rows, from rows_offset_
  std::vector<size_t> rows_offset_;
  std::vector<double> weight_, p1_;           // per owned (node, block)
  std::vector<std::array<double, 6>> sigma_;  // per owned (node, block), Voigt
  Mat M_ = nullptr;
  Vec lumped_ = nullptr;
  std::array<Vec, 6> b_{}, x_{};
  KSP ksp_ = nullptr;
  double seconds_ = 0.0;
  int iterations_ = 0;
  void release_();  // destroys the PETSc objects
  PetscInt row_(int node, int block) const { return PetscInt(nb_) * model_.new_index(node) + block; }
};

}  // namespace angio::solid
