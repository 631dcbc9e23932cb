#include "angio/solid/matrix_slots.hpp"

#include <algorithm>
#include <utility>

#include "petsc_check.hpp"

namespace angio::solid {
namespace {

// A block's CSR index arrays (its rows' starts and columns), borrowed from PETSc until release().
struct Csr {
  Mat A = nullptr;
  PetscInt n = 0;
  const PetscInt *ia = nullptr, *ja = nullptr;
  bool borrow(Mat m) {
    A = m;
    PetscBool done = PETSC_FALSE;
    ANGIO_PETSC(MatGetRowIJ(A, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
    return done == PETSC_TRUE;
  }
  void release() {
    PetscBool done = PETSC_FALSE;
    if (A) ANGIO_PETSC(MatRestoreRowIJ(A, 0, PETSC_FALSE, PETSC_FALSE, &n, &ia, &ja, &done));
    A = nullptr;
  }
  // The position of column c in row r, or -1.
  PetscInt find(PetscInt r, PetscInt c) const {
    const PetscInt* b = ja + ia[r];
    const PetscInt* e = ja + ia[r + 1];
    const PetscInt* p = std::lower_bound(b, e, c);
    return (p != e && *p == c) ? PetscInt(p - ja) : -1;
  }
  // The three rows of every block row hold the same columns, each node's three columns adjacent
  // (`column` maps a block column to the node of its first column, or -1 if it is not one).
  template <class F>
  bool node_blocked(PetscInt block_rows, F column) const {
    for (PetscInt a = 0; a < block_rows; ++a) {
      const PetscInt r = 3 * a, len = ia[r + 1] - ia[r];
      if (len % 3 || ia[r + 2] - ia[r + 1] != len || ia[r + 3] - ia[r + 2] != len) return false;
      for (PetscInt k = 0; k < len; ++k) {
        const PetscInt c = ja[ia[r] + k];
        if (ja[ia[r + 1] + k] != c || ja[ia[r + 2] + k] != c) return false;
        if (k % 3 == 0 && column(c) < 0) return false;
        if (k % 3 && c != ja[ia[r] + k - 1] + 1) return false;
      }
    }
    return true;
  }
};

}  // namespace

void MatrixSlots::set_items(int node_begin, int node_end, std::vector<int> offsets, std::vector<PetscInt> nodes) {
  ready_ = false;
  node_begin_ = node_begin;
  node_end_ = node_end;
  offsets_ = std::move(offsets);
  nodes_ = std::move(nodes);
}

bool MatrixSlots::build(Mat K) {
  ready_ = false;
  K_ = K;
  PetscBool mpi = PETSC_FALSE, seq = PETSC_FALSE;
  ANGIO_PETSC(PetscObjectTypeCompare((PetscObject)K, MATMPIAIJ, &mpi));
  ANGIO_PETSC(PetscObjectTypeCompare((PetscObject)K, MATSEQAIJ, &seq));
  const PetscInt* garray = nullptr;
  if (mpi) {
    ANGIO_PETSC(MatMPIAIJGetSeqAIJ(K, &diag_, &off_, &garray));
  } else if (seq) {
    diag_ = K;
    off_ = nullptr;
  } else {
    return false;
  }
  const PetscInt block_rows = node_end_ - node_begin_;
  Csr d, o;
  bool ok = d.borrow(diag_) && d.n == 3 * block_rows;
  // the off-diagonal block's columns are compressed: global column garray[k] is its column k
  std::vector<std::pair<PetscInt, PetscInt>> compressed;
  if (ok && off_) {
    ok = o.borrow(off_) && o.n == 3 * block_rows;
    PetscInt ncols = 0;
    ANGIO_PETSC(MatGetLocalSize(off_, nullptr, &ncols));
    for (PetscInt k = 0; k < ncols; ++k) compressed.emplace_back(garray[k], k);
    std::sort(compressed.begin(), compressed.end());
  }
  auto off_column = [&](PetscInt global) -> PetscInt {
    auto p = std::lower_bound(compressed.begin(), compressed.end(), std::make_pair(global, PetscInt(-1)));
    return (p != compressed.end() && p->first == global) ? p->second : -1;
  };
  ok = ok && d.node_blocked(block_rows, [](PetscInt c) { return c % 3 == 0 ? c / 3 : -1; });
  if (ok && off_) {
    // compressed columns of one node are adjacent (garray ascends), the first at a multiple of 3
    ok = o.node_blocked(block_rows, [&](PetscInt k) {
      const PetscInt g = garray[k];
      return (g % 3 == 0 && off_column(g + 1) == k + 1 && off_column(g + 2) == k + 2) ? g / 3 : -1;
    });
  }
  slot_start_.assign(1, 0);
  slot_.clear();
  for (size_t i = 0; ok && i + 1 < offsets_.size(); ++i) {
    const int n = offsets_[i + 1] - offsets_[i];
    const PetscInt* nd = nodes_.data() + offsets_[i];
    for (int a = 0; a < n; ++a) {
      const PetscInt pa = nd[a];
      const bool owned = pa >= node_begin_ && pa < node_end_;
      for (int b = 0; b < n; ++b) {
        int code = 0;
        if (owned) {
          const PetscInt r = 3 * (pa - node_begin_), pb = nd[b];
          if (pb >= node_begin_ && pb < node_end_) {
            const PetscInt at = d.find(r, 3 * (pb - node_begin_));
            ok = ok && at >= 0;
            code = int(at - d.ia[r]);
          } else {
            const PetscInt k = off_ ? off_column(3 * pb) : -1;
            const PetscInt at = k >= 0 ? o.find(r, k) : -1;
            ok = ok && at >= 0;
            code = -int(at - (off_ ? o.ia[r] : 0)) - 1;
          }
        }
        slot_.push_back(code);
      }
    }
    slot_start_.push_back(slot_.size());
  }
  if (ok) {
    diag_rows_.assign(d.ia, d.ia + d.n + 1);
    diag_nz_ = d.ia[d.n];
    off_rows_.clear();
    off_nz_ = 0;
    if (off_) {
      off_rows_.assign(o.ia, o.ia + o.n + 1);
      off_nz_ = o.ia[o.n];
    }
  } else {
    slot_.clear();
    slot_start_.clear();
  }
  d.release();
  o.release();
  ready_ = ok;
  return ok;
}

bool MatrixSlots::begin(Mat K) {
  if (!ready(K)) return false;
  // an entry inserted outside the pattern since build() moved the entries behind it
  Csr d, o;
  bool same = d.borrow(diag_) && d.ia[d.n] == diag_nz_;
  if (off_) same = same && o.borrow(off_) && o.ia[o.n] == off_nz_;
  d.release();
  o.release();
  if (!same && !build(K_)) return false;
  ANGIO_PETSC(MatSeqAIJGetArray(diag_, &diag_values_));
  if (off_) ANGIO_PETSC(MatSeqAIJGetArray(off_, &off_values_));
  return true;
}

void MatrixSlots::add(size_t i, const Eigen::MatrixXd& Ke, const std::vector<PetscInt>& dofs) {
  const int n = offsets_[i + 1] - offsets_[i], m = 3 * n;
  const PetscInt* nd = nodes_.data() + offsets_[i];
  const int* s = slot_.data() + slot_start_[i];
  for (int a = 0; a < n; ++a) {
    const PetscInt pa = nd[a];
    if (pa < node_begin_ || pa >= node_end_) {
      rows_elsewhere_.resize(3 * size_t(m));
      for (int c = 0; c < m; ++c)
        for (int k = 0; k < 3; ++k) rows_elsewhere_[3 * c + k] = Ke(3 * a + k, c);
      ANGIO_PETSC(MatSetValues(K_, 3, dofs.data() + 3 * a, m, dofs.data(), rows_elsewhere_.data(), ADD_VALUES));
      continue;
    }
    const PetscInt r = 3 * (pa - node_begin_);
    for (int b = 0; b < n; ++b) {
      const int code = s[a * n + b];
      PetscScalar* values = code >= 0 ? diag_values_ : off_values_;
      const PetscInt* rows = code >= 0 ? diag_rows_.data() : off_rows_.data();
      const PetscInt at = code >= 0 ? code : -code - 1;
      for (int k = 0; k < 3; ++k) {
        PetscScalar* v = values + rows[r + k] + at;
        for (int j = 0; j < 3; ++j) v[j] += Ke(3 * a + k, 3 * b + j);
      }
    }
  }
}

void MatrixSlots::end() {
  if (diag_values_) ANGIO_PETSC(MatSeqAIJRestoreArray(diag_, &diag_values_));
  if (off_values_) ANGIO_PETSC(MatSeqAIJRestoreArray(off_, &off_values_));
  diag_values_ = off_values_ = nullptr;
}

}  // namespace angio::solid
