#include "angio/solid/stress_recovery.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "angio/solid/recovery_kernels.hpp"
#include "petsc_check.hpp"

namespace angio::solid {

StressRecovery::StressRecovery(const SolidModel& model, Mass mass) : model_(model), mass_(mass) {
  const Mesh& mesh = model.mesh();
  const MPI_Comm comm = model.comm();
  nb_ = int(mesh.blocks.size());
  const int n0 = model.owned_node_begin(), n1 = model.owned_node_end();
  nloc_ = n1 - n0;
  const PetscInt rows = PetscInt(nb_) * nloc_, r0 = PetscInt(nb_) * n0, r1 = PetscInt(nb_) * n1;
  const PetscInt total = PetscInt(nb_) * PetscInt(mesh.X.size());
  // Preallocation: the columns of each owned row from all elements (every rank holds the whole
  // mesh; the model's own matrix is preallocated the same way, SolidModel::setup_petsc_).
  std::vector<std::vector<PetscInt>> cols(rows);
  for (const auto& el : mesh.elements)
    for (int a = 0; a < el.nn(); ++a) {
      const int p = model.new_index(el.n[a]);
      if (p < n0 || p >= n1) continue;
      auto& c = cols[size_t(p - n0) * nb_ + el.block];
      for (int b = 0; b < el.nn(); ++b) c.push_back(row_(el.n[b], el.block));
    }
  std::vector<PetscInt> dnnz(rows), onnz(rows);
  for (PetscInt r = 0; r < rows; ++r) {
    auto& c = cols[r];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    PetscInt d = 0;
    for (PetscInt j : c) d += (j >= r0 && j < r1);
    dnnz[r] = c.empty() ? 1 : d;  // a (node, block) pair that does not exist: identity row
    onnz[r] = PetscInt(c.size()) - d;
  }
  ANGIO_PETSC(MatCreate(comm, &M_));
  ANGIO_PETSC(MatSetSizes(M_, rows, rows, total, total));
  ANGIO_PETSC(MatSetType(M_, MATAIJ));
  ANGIO_PETSC(MatXAIJSetPreallocation(M_, 1, dnnz.data(), onnz.data(), nullptr, nullptr));
  ANGIO_PETSC(MatSetOption(M_, MAT_ROW_ORIENTED, PETSC_FALSE));  // Eigen is column-major
  Vec w;
  ANGIO_PETSC(MatCreateVecs(M_, &w, nullptr));
  ANGIO_PETSC(VecSet(w, 0.0));
  Eigen::MatrixXd X, Me;
  std::vector<PetscInt> idx;
  std::vector<PetscScalar> share;
  const auto& le = model.local_elements();
  gauss_offset_.resize(le.size());
  load_offset_.resize(le.size());
  rows_offset_.resize(le.size());
  size_t offset = 0;
  std::vector<Mat3> unit;
  Eigen::MatrixXd be;
  for (size_t i = 0; i < le.size(); ++i) {
    const auto& el = mesh.elements[le[i]];
    const int ng = int(volume_rule(el.type).size());
    if (ng > 8 || el.nn() > 10)  // the capacity of recover()'s element buffers
      throw std::invalid_argument("stress recovery: an element with more than 10 nodes or 8 Gauss points");
    gauss_offset_[i] = offset;
    offset += ng;
    X.resize(el.nn(), 3);
    idx.resize(el.nn());
    for (int a = 0; a < el.nn(); ++a) {
      X.row(a) = mesh.X[el.n[a]].transpose();
      idx[a] = row_(el.n[a], el.block);
    }
    rows_offset_[i] = rows_.size();
    rows_.insert(rows_.end(), idx.begin(), idx.end());
    // column g of B_e: the 11-column of b for a unit σ_11 at Gauss point g alone
    load_offset_[i] = load_.size();
    for (int g = 0; g < ng; ++g) {
      unit.assign(ng, Mat3::Zero());
      unit[g](0, 0) = 1.0;
      recovery_element(el.type, X, unit.data(), nullptr, &be);
      load_.insert(load_.end(), be.col(0).data(), be.col(0).data() + el.nn());
    }
    const double V = recovery_element(el.type, X, nullptr, &Me, nullptr);
    share.assign(el.nn(), V / el.nn());
    ANGIO_PETSC(MatSetValues(M_, el.nn(), idx.data(), el.nn(), idx.data(), Me.data(), ADD_VALUES));
    ANGIO_PETSC(VecSetValues(w, el.nn(), idx.data(), share.data(), ADD_VALUES));
  }
  for (PetscInt r = 0; r < rows; ++r)
    if (cols[r].empty()) ANGIO_PETSC(MatSetValue(M_, r0 + r, r0 + r, 1.0, ADD_VALUES));
  ANGIO_PETSC(MatAssemblyBegin(M_, MAT_FINAL_ASSEMBLY));
  ANGIO_PETSC(VecAssemblyBegin(w));
  ANGIO_PETSC(MatAssemblyEnd(M_, MAT_FINAL_ASSEMBLY));
  ANGIO_PETSC(VecAssemblyEnd(w));
  {
    const PetscScalar* a;
    ANGIO_PETSC(VecGetArrayRead(w, &a));
    weight_.assign(a, a + rows);
    ANGIO_PETSC(VecRestoreArrayRead(w, &a));
  }
  for (PetscInt r = 0; r < rows; ++r)
    if (cols[r].empty()) weight_[r] = 0.0;
  VecDestroy(&w);
  for (int k = 0; k < 6; ++k) {
    ANGIO_PETSC(MatCreateVecs(M_, &x_[k], &b_[k]));
    ANGIO_PETSC(VecSet(x_[k], 0.0));
  }
  if (mass_ == Mass::lumped) {
    ANGIO_PETSC(VecDuplicate(x_[0], &lumped_));
    ANGIO_PETSC(MatGetRowSum(M_, lumped_));
    const PetscScalar* m;
    ANGIO_PETSC(VecGetArrayRead(lumped_, &m));
    int bad = 0, any = 0;
    for (PetscInt r = 0; r < rows; ++r) bad |= weight_[r] > 0.0 && !(m[r] > 0.0);
    ANGIO_PETSC(VecRestoreArrayRead(lumped_, &m));
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, comm);
    if (any) {
      release_();  // the destructor does not run for a constructor that throws
      throw std::runtime_error(
          "stress recovery: the lumped mass has non-positive row sums (tet10 vertices); use the "
          "consistent projection");
    }
  } else {
    ANGIO_PETSC(KSPCreate(comm, &ksp_));
    ANGIO_PETSC(KSPSetOperators(ksp_, M_, M_));
    ANGIO_PETSC(KSPSetType(ksp_, KSPCG));
    PC pc;
    ANGIO_PETSC(KSPGetPC(ksp_, &pc));
    ANGIO_PETSC(PCSetType(pc, PCJACOBI));
    // relative to ||b||: the small stresses of a soft layer next to a stiff one (the same system)
    // keep ~1e-12 × κ(M) of the largest ones, κ ≈ 27 for Jacobi-scaled hex8 mass matrices
    ANGIO_PETSC(KSPSetTolerances(ksp_, 1e-12, 1e-300, PETSC_DEFAULT, 2000));
    ANGIO_PETSC(KSPSetInitialGuessNonzero(ksp_, PETSC_TRUE));  // the previous call's solution
    ANGIO_PETSC(KSPSetUp(ksp_));
  }
  sigma_.assign(rows, {0, 0, 0, 0, 0, 0});
  p1_.assign(rows, std::numeric_limits<double>::quiet_NaN());
}

StressRecovery::~StressRecovery() { release_(); }

void StressRecovery::release_() {
  if (ksp_) KSPDestroy(&ksp_);
  if (M_) MatDestroy(&M_);
  if (lumped_) VecDestroy(&lumped_);
  for (int k = 0; k < 6; ++k) {
    if (b_[k]) VecDestroy(&b_[k]);
    if (x_[k]) VecDestroy(&x_[k]);
  }
}

bool StressRecovery::recover(const std::vector<Mat3>& gauss) {
  const double t0 = MPI_Wtime();
  const Mesh& mesh = model_.mesh();
  const auto& le = model_.local_elements();
  const size_t expected = le.empty() ? 0 : gauss_offset_.back() + volume_rule(mesh.elements[le.back()].type).size();
  if (gauss.size() != expected)
    throw std::invalid_argument("stress recovery: " + std::to_string(gauss.size()) +
                                " Gauss-point stresses, expected " + std::to_string(expected));
  for (int k = 0; k < 6; ++k) ANGIO_PETSC(VecSet(b_[k], 0.0));
  // b_e = B_e S_e; fixed-capacity buffers (at most 10 nodes, 8 Gauss points): no allocation per element
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::ColMajor, 8, 6> S;
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::ColMajor, 10, 6> be;
  for (size_t i = 0; i < le.size(); ++i) {
    const auto& el = mesh.elements[le[i]];
    const int n = el.nn(), ng = int(volume_rule(el.type).size());
    const Mat3* sg = gauss.data() + gauss_offset_[i];
    S.resize(ng, 6);
    for (int g = 0; g < ng; ++g)
      for (int k = 0; k < 6; ++k) S(g, k) = sg[g](kVoigt[k][0], kVoigt[k][1]);
    be.noalias() = Eigen::Map<const Eigen::MatrixXd>(load_.data() + load_offset_[i], n, ng) * S;
    for (int k = 0; k < 6; ++k)
      ANGIO_PETSC(VecSetValues(b_[k], n, rows_.data() + rows_offset_[i], be.col(k).data(), ADD_VALUES));
  }
  for (int k = 0; k < 6; ++k) ANGIO_PETSC(VecAssemblyBegin(b_[k]));
  for (int k = 0; k < 6; ++k) ANGIO_PETSC(VecAssemblyEnd(b_[k]));
  bool ok = true;
  iterations_ = 0;
  for (int k = 0; k < 6; ++k) {
    if (mass_ == Mass::lumped) {
      ANGIO_PETSC(VecPointwiseDivide(x_[k], b_[k], lumped_));
      continue;
    }
    ANGIO_PETSC(KSPSolve(ksp_, b_[k], x_[k]));
    KSPConvergedReason reason;
    PetscInt its;
    ANGIO_PETSC(KSPGetConvergedReason(ksp_, &reason));
    ANGIO_PETSC(KSPGetIterationNumber(ksp_, &its));
    iterations_ += int(its);
    ok = ok && reason > 0;
  }
  const size_t rows = size_t(nb_) * nloc_;
  for (int k = 0; k < 6; ++k) {
    const PetscScalar* a;
    ANGIO_PETSC(VecGetArrayRead(x_[k], &a));
    for (size_t r = 0; r < rows; ++r) sigma_[r][k] = a[r];
    ANGIO_PETSC(VecRestoreArrayRead(x_[k], &a));
  }
  for (size_t r = 0; r < rows; ++r) {
    if (!(weight_[r] > 0.0)) continue;
    const Mat3 s = stress(int(r / nb_), int(r % nb_));
    p1_[r] = Eigen::SelfAdjointEigenSolver<Mat3>(s, Eigen::EigenvaluesOnly).eigenvalues()(2);
  }
  seconds_ = MPI_Wtime() - t0;
  return ok;
}

Mat3 StressRecovery::stress(int i, int b) const {
  const auto& v = sigma_[size_t(i) * nb_ + b];
  Mat3 s;
  for (int k = 0; k < 6; ++k) s(kVoigt[k][0], kVoigt[k][1]) = s(kVoigt[k][1], kVoigt[k][0]) = v[k];
  return s;
}

std::vector<double> StressRecovery::p1_field(int b) const {
  std::vector<double> f(nloc_);
  for (int i = 0; i < nloc_; ++i) f[i] = p1(i, b);
  return f;
}

}  // namespace angio::solid
