#pragma once
// Where each element's node-pair blocks sit in the storage of an assembled AIJ matrix, so that the
// element tangents of every later assembly are added straight into the matrix's value arrays.
//
// Why: PETSc's MatSetValues finds each of an element's (3n)^2 entries by a search in its row (about
// 30 ns per entry here); on the 0.25 mm patient artery (67,619 tet10 on 2 ranks) that was 0.9 s of a
// 1.9 s tangent assembly, the element kernels 0.25 s (docs/performance.md, "Element insertion").
// The solid's matrix is node-blocked (create_matrix_: the three rows of a node share one column
// set, and the three columns of a node are adjacent), so one offset per node pair serves its 3 x 3
// block; the slots are found once per pattern (a matrix rebuilt by contact pairs) and hold n^2
// integers per element.
//
// Rows this rank owns are written directly; an element's rows owned by another rank go through
// MatSetValues as before (PETSc's stash carries them to their owner at the final assembly).
#include <petscmat.h>

#include <Eigen/Dense>
#include <vector>

namespace angio::solid {

class MatrixSlots {
 public:
  // The items whose matrices add() places (nodes in the matrix's block numbering, item after item:
  // item i has the nodes nodes[offsets[i] .. offsets[i+1])) and the block rows [node_begin, node_end)
  // this rank owns. Once: they do not change with the matrix's pattern.
  void set_items(int node_begin, int node_end, std::vector<int> offsets, std::vector<PetscInt> nodes);
  // Finds the items' slots in K, a (Seq|MPI)AIJ matrix with block size 3 assembled with its whole
  // pattern. False (and no slots) where K is of another type or its pattern is not node-blocked: the
  // caller then inserts with MatSetValues.
  bool build(Mat K);
  bool ready(Mat K) const { return ready_ && K == K_; }

  // Between begin() and end() (K's value arrays open), add() adds item i's matrix Ke (column-major,
  // 3n x 3n, dofs of node a at 3a..3a+2) at K's entries; `dofs` are its 3n global dof indices for
  // the rows owned elsewhere. begin() finds the slots again if K's pattern has changed since build()
  // (an entry inserted outside it), and returns false, opening nothing, where there are none for K.
  bool begin(Mat K);
  void add(size_t i, const Eigen::MatrixXd& Ke, const std::vector<PetscInt>& dofs);
  void end();

 private:
  Mat K_ = nullptr, diag_ = nullptr, off_ = nullptr;  // K, its diagonal and off-diagonal blocks (off_: none on 1 rank)
  bool ready_ = false;
  int node_begin_ = 0, node_end_ = 0;
  std::vector<int> offsets_;
  std::vector<PetscInt> nodes_;
  // per item, per node pair (a, b) row-major: the offset of node b's first column in the rows of
  // node a, >= 0 in the diagonal block, -(offset + 1) in the off-diagonal one; unused for rows elsewhere
  std::vector<int> slot_;
  std::vector<size_t> slot_start_;              // item i's node pairs from slot_[slot_start_[i]]
  std::vector<PetscInt> diag_rows_, off_rows_;  // row starts (CSR) of the owned rows in each block
  PetscInt diag_nz_ = 0, off_nz_ = 0;           // entries of each block at build(): a changed pattern is detected
  PetscScalar *diag_values_ = nullptr, *off_values_ = nullptr;
  std::vector<PetscScalar> rows_elsewhere_;  // one node's three rows of Ke, column-major, for MatSetValues
};

}  // namespace angio::solid
