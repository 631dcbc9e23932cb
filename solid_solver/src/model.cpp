#include "angio/solid/model.hpp"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "angio/solid/load_direction.hpp"
#include "angio/solid/petsc_options_check.hpp"
#include "petsc_check.hpp"

namespace angio::solid {

const char* petsc_default_options() {
  return "-ksp_type gmres -ksp_gmres_restart 200 -ksp_rtol 1e-6 -ksp_atol 1e-14 -ksp_max_it 1000 "
         "-pc_type bjacobi -sub_pc_type ilu -sub_pc_factor_levels 1";
}

namespace {
// RAII push of the model's private options database (so several models in one process, e.g. in
// tests, do not see each other's options).
struct OptionsScope {
  explicit OptionsScope(PetscOptions o) : o_(o) { PetscOptionsPush(o_); }
  ~OptionsScope() { PetscOptionsPop(); }
  PetscOptions o_;
};

double norm2(Vec v) {
  PetscReal n;
  ANGIO_PETSC(VecNorm(v, NORM_2, &n));
  return double(n);
}
}  // namespace

SolidModel::SolidModel(MPI_Comm comm, Mesh mesh, std::vector<LayerMaterial> mats, ModelOptions options)
    : comm_(comm), mesh_(std::move(mesh)), materials_(std::move(mats)), opt_(std::move(options)) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  if (materials_.size() != mesh_.blocks.size())
    throw std::runtime_error("solid model: " + std::to_string(mesh_.blocks.size()) + " blocks but " +
                             std::to_string(materials_.size()) + " materials");
  // reference Jacobians must be positive (the scene reader refuses inverted meshes; this guards
  // meshes built in code)
  if (const std::string bad = first_invalid_element(mesh_); !bad.empty())
    throw std::runtime_error("solid mesh: " + bad);
  std::vector<double> volume(mesh_.elements.size(), 0.0);  // reference volume per element
  {
    Eigen::VectorXd N;
    Eigen::MatrixXd dN, X;
    for (size_t e = 0; e < mesh_.elements.size(); ++e) {
      const auto& el = mesh_.elements[e];
      X.resize(el.nn(), 3);
      for (int a = 0; a < el.nn(); ++a) X.row(a) = mesh_.X[el.n[a]].transpose();
      for (const auto& qp : volume_rule(el.type)) {
        shape(el.type, qp.xi, N, dN);
        const double detJ = (X.transpose() * dN).determinant();
        volume[e] += qp.w * detJ;
      }
    }
  }
  partition_();
  // fiber families of this rank's elements only: what the kernels read (whole-mesh per rank otherwise)
  fibers_.resize(local_elements_.size());
  for (size_t i = 0; i < local_elements_.size(); ++i) {
    const int e = local_elements_[i];
    const auto& mat = materials_[mesh_.elements[e].block];
    if (!mat.fibers.empty())
      fibers_[i] = resolve_fibers(
          mat, mesh_.frames.size() == mesh_.elements.size() ? mesh_.frames[e] : element_frame(mesh_, e, opt_.axis));
  }
  setup_petsc_();
  if (opt_.newton.damping > 0.0) {
    // η·V_a per dof: each owned element adds η·V_e/n_e to its nodes (a lumped "mass" of unit density)
    ANGIO_PETSC(VecDuplicate(r_, &damping_diag_));
    ANGIO_PETSC(VecSet(damping_diag_, 0.0));
    const auto& parts = opt_.newton.damping_parts;
    std::vector<char> damped(mesh_.blocks.size());  // per block, decided once
    for (size_t b = 0; b < damped.size(); ++b)
      damped[b] = parts.empty() || std::find(parts.begin(), parts.end(), mesh_.blocks[b].part) != parts.end();
    for (int e : local_elements_) {
      const auto& el = mesh_.elements[e];
      if (!damped[el.block]) continue;
      const double m = opt_.newton.damping * volume[e] / el.nn();
      for (int a = 0; a < el.nn(); ++a)
        for (int k = 0; k < 3; ++k) ANGIO_PETSC(VecSetValue(damping_diag_, 3 * perm_[el.n[a]] + k, m, ADD_VALUES));
    }
    ANGIO_PETSC(VecAssemblyBegin(damping_diag_));
    ANGIO_PETSC(VecAssemblyEnd(damping_diag_));
    ANGIO_PETSC(VecDuplicate(damping_diag_, &damping_tangent_));
  }
  u_.assign(3 * held_.size(), 0.0);
  u_committed_ = u_;
  visc_offset_.assign(local_elements_.size(), -1);
  int nvisc = 0;
  for (size_t i = 0; i < local_elements_.size(); ++i) {
    const auto& el = mesh_.elements[local_elements_[i]];
    if (!materials_[el.block].viscous) continue;
    visc_offset_[i] = nvisc;
    nvisc += int(volume_rule(el.type).size());
  }
  visc_Q_.assign(nvisc, Vec6::Zero());  // the reference state is stress-free
  visc_S_.assign(nvisc, Vec6::Zero());
}

const ViscousHistory* SolidModel::viscous_history_(size_t i, ViscousHistory& h) const {
  if (visc_offset_[i] < 0) return nullptr;
  const auto& el = mesh_.elements[local_elements_[i]];
  h.branch = *materials_[el.block].viscous;
  h.dt = time_ - committed_time_;
  h.Q_n = visc_Q_.data() + visc_offset_[i];
  h.S_n = visc_S_.data() + visc_offset_[i];
  h.Q_out = h.S_out = nullptr;
  return &h;
}

SolidModel::~SolidModel() {
  if (ksp_) KSPDestroy(&ksp_);
  if (K_) MatDestroy(&K_);
  if (r_) VecDestroy(&r_);
  if (du_) VecDestroy(&du_);
  if (damping_diag_) VecDestroy(&damping_diag_);
  if (damping_tangent_) VecDestroy(&damping_tangent_);
  if (full_) VecDestroy(&full_);
  if (scatter_) VecScatterDestroy(&scatter_);
  if (options_) PetscOptionsDestroy(&options_);
}

void SolidModel::partition_() {
  const int ne = int(mesh_.elements.size()), nn = int(mesh_.X.size());
  elem_rank_.assign(ne, 0);
  if (size_ > 1 && opt_.partitioner != "contiguous") {
    // element dual graph (shared faces)
    std::unordered_map<long long, int> first;
    std::vector<std::vector<int>> adj(ne);
    for (int e = 0; e < ne; ++e) {
      const auto& el = mesh_.elements[e];
      for (const auto& lf : local_faces(el.type)) {
        std::array<int, 4> c{};
        const int nc = num_corners(lf.type);
        for (int a = 0; a < nc; ++a) c[a] = el.n[lf.nodes[a]];
        for (int a = 1; a < nc; ++a)
          for (int b = a; b > 0 && c[b - 1] > c[b]; --b) std::swap(c[b - 1], c[b]);
        const long long key = (long long)c[0] * 1000003LL * 1000003LL + (long long)c[1] * 1000003LL + c[2];
        auto [it, fresh] = first.emplace(key, e);
        if (!fresh) {
          adj[e].push_back(it->second);
          adj[it->second].push_back(e);
        }
      }
    }
    const int e0 = int((long long)ne * rank_ / size_), e1 = int((long long)ne * (rank_ + 1) / size_);
    PetscInt *ia, *ja;
    PetscInt nnz = 0;
    for (int e = e0; e < e1; ++e) nnz += PetscInt(adj[e].size());
    ANGIO_PETSC(PetscMalloc1(e1 - e0 + 1, &ia));
    ANGIO_PETSC(PetscMalloc1(std::max<PetscInt>(nnz, 1), &ja));
    ia[0] = 0;
    for (int e = e0; e < e1; ++e) {
      std::sort(adj[e].begin(), adj[e].end());
      ia[e - e0 + 1] = ia[e - e0] + PetscInt(adj[e].size());
      std::copy(adj[e].begin(), adj[e].end(), ja + ia[e - e0]);
    }
    Mat A;
    ANGIO_PETSC(MatCreateMPIAdj(comm_, e1 - e0, ne, ia, ja, nullptr, &A));
    MatPartitioning part;
    ANGIO_PETSC(MatPartitioningCreate(comm_, &part));
    ANGIO_PETSC(MatPartitioningSetAdjacency(part, A));
    ANGIO_PETSC(MatPartitioningSetType(part, opt_.partitioner.c_str()));
    IS is, isall;
    ANGIO_PETSC(MatPartitioningApply(part, &is));
    ANGIO_PETSC(ISAllGather(is, &isall));
    const PetscInt* idx;
    ANGIO_PETSC(ISGetIndices(isall, &idx));
    for (int e = 0; e < ne; ++e) elem_rank_[e] = int(idx[e]);
    ANGIO_PETSC(ISRestoreIndices(isall, &idx));
    ISDestroy(&is);
    ISDestroy(&isall);
    MatPartitioningDestroy(&part);
    MatDestroy(&A);
  } else {
    for (int e = 0; e < ne; ++e) elem_rank_[e] = int((long long)e * size_ / std::max(ne, 1));
  }
  node_owner_.assign(nn, size_);
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh_.elements[e];
    for (int a = 0; a < el.nn(); ++a) node_owner_[el.n[a]] = std::min(node_owner_[el.n[a]], elem_rank_[e]);
  }
  for (auto& o : node_owner_)
    if (o == size_) o = 0;  // unreferenced node
  perm_.assign(nn, 0);
  iperm_.assign(nn, 0);
  std::vector<int> count(size_ + 1, 0);
  for (int o : node_owner_) ++count[o + 1];
  for (int r = 0; r < size_; ++r) count[r + 1] += count[r];
  node_begin_ = count[rank_];
  node_end_ = count[rank_ + 1];
  std::vector<int> next(count.begin(), count.end() - 1);
  for (int i = 0; i < nn; ++i) {
    perm_[i] = next[node_owner_[i]]++;
    iperm_[perm_[i]] = i;
  }
  local_elements_.clear();
  for (int e = 0; e < ne; ++e)
    if (elem_rank_[e] == rank_) local_elements_.push_back(e);
  // held: the owned nodes in order, then the other nodes of the local elements (ascending)
  slot_.assign(nn, -1);
  held_.clear();
  for (int i = node_begin_; i < node_end_; ++i) {
    slot_[iperm_[i]] = int(held_.size());
    held_.push_back(i);
  }
  std::vector<PetscInt> ghosts;
  for (int e : local_elements_) {
    const auto& el = mesh_.elements[e];
    for (int a = 0; a < el.nn(); ++a)
      if (slot_[el.n[a]] < 0) ghosts.push_back(perm_[el.n[a]]);
  }
  std::sort(ghosts.begin(), ghosts.end());
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  for (PetscInt g : ghosts) {
    slot_[iperm_[g]] = int(held_.size());
    held_.push_back(g);
  }
  // the local elements' nodes in the new numbering, where their tangents go (create_matrix_ finds the slots)
  std::vector<int> offsets{0};
  std::vector<PetscInt> element_nodes;
  for (int e : local_elements_) {
    const auto& el = mesh_.elements[e];
    for (int a = 0; a < el.nn(); ++a) element_nodes.push_back(perm_[el.n[a]]);
    offsets.push_back(int(element_nodes.size()));
  }
  slots_.set_items(node_begin_, node_end_, std::move(offsets), std::move(element_nodes));
}

void SolidModel::set_contact(ContactModel* contact) {
  contact_ = contact;
  if (!contact) return;
  hold_nodes(contact->held_nodes(*this));
  extra_ = contact->couplings(*this);
  if (!extra_.empty()) create_matrix_();
}

void SolidModel::create_matrix_() {
  const int nloc = node_end_ - node_begin_;
  // column nodes (new numbering) of each owned row node
  std::vector<std::vector<PetscInt>> nbr(nloc);
  auto couple = [&](const int* rows, int nr, const int* cols, int nc) {
    for (int a = 0; a < nr; ++a) {
      const int pa = perm_[rows[a]];
      if (pa < node_begin_ || pa >= node_end_) continue;
      auto& v = nbr[pa - node_begin_];
      for (int b = 0; b < nc; ++b) v.push_back(perm_[cols[b]]);
    }
  };
  for (const auto& el : mesh_.elements) couple(el.n.data(), el.nn(), el.n.data(), el.nn());
  for (const auto& c : extra_) couple(c.rows.data(), int(c.rows.size()), c.cols.data(), int(c.cols.size()));
  std::vector<PetscInt> dnnz(nloc), onnz(nloc);
  size_t widest = 0;
  for (int i = 0; i < nloc; ++i) {
    auto& v = nbr[i];
    v.push_back(node_begin_ + i);  // the diagonal, also of a node in no element
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    widest = std::max(widest, v.size());
    int d = 0;
    for (PetscInt j : v) d += (j >= node_begin_ && j < node_end_);
    dnnz[i] = d;
    onnz[i] = PetscInt(v.size()) - d;
  }
  if (K_) MatDestroy(&K_);
  ANGIO_PETSC(MatCreate(comm_, &K_));
  ANGIO_PETSC(MatSetSizes(K_, 3 * nloc, 3 * nloc, num_dofs(), num_dofs()));
  ANGIO_PETSC(MatSetType(K_, MATAIJ));
  ANGIO_PETSC(MatSetBlockSize(K_, 3));
  ANGIO_PETSC(MatXAIJSetPreallocation(K_, 3, dnnz.data(), onnz.data(), nullptr, nullptr));
  // an entry outside the pattern is still accepted (at the price of a reallocation), not an error
  ANGIO_PETSC(MatSetOption(K_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  ANGIO_PETSC(MatSetOption(K_, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
  ANGIO_PETSC(MatSetOption(K_, MAT_ROW_ORIENTED, PETSC_FALSE));  // Eigen is column-major
  // the whole pattern inserted once: the first assembly would otherwise squeeze out what it did not touch
  const std::vector<PetscScalar> zeros(9 * widest, 0.0);
  for (int i = 0; i < nloc; ++i) {
    const PetscInt row = node_begin_ + i;
    ANGIO_PETSC(MatSetValuesBlocked(K_, 1, &row, PetscInt(nbr[i].size()), nbr[i].data(), zeros.data(), INSERT_VALUES));
  }
  ANGIO_PETSC(MatAssemblyBegin(K_, MAT_FINAL_ASSEMBLY));
  ANGIO_PETSC(MatAssemblyEnd(K_, MAT_FINAL_ASSEMBLY));
  slots_.build(K_);
  // rigid-body near null space (for GAMG; harmless otherwise)
  std::vector<PetscInt> owned(nloc);
  std::iota(owned.begin(), owned.end(), node_begin_);
  MatNullSpace nsp = rigid_body_modes_(owned);
  ANGIO_PETSC(MatSetNearNullSpace(K_, nsp));
  MatNullSpaceDestroy(&nsp);
  if (ksp_) ANGIO_PETSC(KSPSetOperators(ksp_, K_, K_));
  pc_current_ = false;
  pattern_ = std::move(nbr);
}

bool SolidModel::grow_pattern_(const std::vector<NodeCoupling>& needed) {
  // every rank's new couplings to every rank (a pair evaluated here may add to rows owned elsewhere),
  // flattened as [#rows, #cols, rows..., cols...] per coupling
  std::vector<int> mine;
  for (const auto& c : needed) {
    mine.push_back(int(c.rows.size()));
    mine.push_back(int(c.cols.size()));
    mine.insert(mine.end(), c.rows.begin(), c.rows.end());
    mine.insert(mine.end(), c.cols.begin(), c.cols.end());
  }
  const int n = int(mine.size());
  std::vector<int> counts(size_), offsets(size_ + 1, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (int k = 0; k < size_; ++k) offsets[k + 1] = offsets[k] + counts[k];
  if (offsets[size_] == 0) return false;
  std::vector<int> all(offsets[size_]);
  MPI_Allgatherv(mine.data(), n, MPI_INT, all.data(), counts.data(), offsets.data(), MPI_INT, comm_);
  auto in_pattern = [&](int row, int col) {
    const int pr = perm_[row];
    if (pr < node_begin_ || pr >= node_end_) return true;  // another rank's row: its owner checks
    const auto& v = pattern_[pr - node_begin_];
    return std::binary_search(v.begin(), v.end(), PetscInt(perm_[col]));
  };
  int grew = 0;
  for (size_t i = 0; i < all.size();) {
    const int nr = all[i], nc = all[i + 1];
    const int* rows = all.data() + i + 2;
    const int* cols = rows + nr;
    i += 2 + nr + nc;
    bool missing = false;
    for (int a = 0; a < nr && !missing; ++a)
      for (int b = 0; b < nc && !missing; ++b) missing = !in_pattern(rows[a], cols[b]);
    if (!missing) continue;
    extra_.push_back({std::vector<int>(rows, rows + nr), std::vector<int>(cols, cols + nc)});
    grew = 1;
  }
  int any = 0;
  MPI_Allreduce(&grew, &any, 1, MPI_INT, MPI_MAX, comm_);
  if (!any) return false;
  create_matrix_();
  ++pattern_rebuilds_;
  return true;
}

void SolidModel::setup_petsc_() {
  create_matrix_();
  ANGIO_PETSC(MatCreateVecs(K_, &du_, &r_));
  ANGIO_PETSC(VecSetBlockSize(du_, 3));
  create_scatter_();
  ANGIO_PETSC(PetscOptionsCreate(&options_));
  ANGIO_PETSC(PetscOptionsInsertString(options_, petsc_default_options()));
  ANGIO_PETSC(PetscOptionsInsertString(options_, opt_.petsc_options.c_str()));
  OptionsScope scope(options_);
  ANGIO_PETSC(KSPCreate(comm_, &ksp_));
  ANGIO_PETSC(KSPSetOperators(ksp_, K_, K_));
  ANGIO_PETSC(KSPSetFromOptions(ksp_));
  PC pc;
  ANGIO_PETSC(KSPGetPC(ksp_, &pc));
  PetscBool split = PETSC_FALSE;
  ANGIO_PETSC(PetscObjectTypeCompare((PetscObject)pc, PCFIELDSPLIT, &split));
  if (split) set_part_splits_(pc);
  const std::vector<std::string> parts = part_names(mesh_);
  for (const auto& name : opt_.newton.reuse_parts) {
    const auto at = std::find(parts.begin(), parts.end(), name);
    if (!split || at == parts.end() || opt_.newton.reuse_preconditioner <= 0 || opt_.newton.modified)
      throw std::invalid_argument("newton.reuse_parts: '" + name +
                                  "' needs -pc_type fieldsplit, a part of the mesh, reuse_preconditioner > 0 "
                                  "and the exact tangent");
    kept_splits_.push_back(int(at - parts.begin()));
  }
}

void SolidModel::keep_splits_(bool keep) {
  // the flag is read by each split's own setup inside the next KSPSolve (the splits exist after the first)
  if (kept_splits_.empty() || !splits_ready_) return;
  PC pc;
  ANGIO_PETSC(KSPGetPC(ksp_, &pc));
  PetscInt n = 0;
  KSP* sub = nullptr;
  ANGIO_PETSC(PCFieldSplitGetSubKSP(pc, &n, &sub));
  for (int k : kept_splits_) ANGIO_PETSC(KSPSetReusePreconditioner(sub[k], keep ? PETSC_TRUE : PETSC_FALSE));
  ANGIO_PETSC(PetscFree(sub));
}

std::vector<std::string> SolidModel::unused_petsc_options() const {
  return solid::unused_petsc_options(options_, opt_.petsc_options);
}

MatNullSpace SolidModel::rigid_body_modes_(const std::vector<PetscInt>& nodes) const {
  Vec coords;
  ANGIO_PETSC(VecCreateMPI(comm_, 3 * PetscInt(nodes.size()), PETSC_DECIDE, &coords));
  ANGIO_PETSC(VecSetBlockSize(coords, 3));
  PetscScalar* c;
  ANGIO_PETSC(VecGetArray(coords, &c));
  for (size_t i = 0; i < nodes.size(); ++i)
    for (int k = 0; k < 3; ++k) c[3 * i + k] = mesh_.X[iperm_[nodes[i]]](k);
  ANGIO_PETSC(VecRestoreArray(coords, &c));
  MatNullSpace nsp;
  ANGIO_PETSC(MatNullSpaceCreateRigidBody(coords, &nsp));
  VecDestroy(&coords);
  return nsp;
}

void SolidModel::set_part_splits_(PC pc) {
  // One split per part of the mesh (Block::part: "balloon", "artery"), named after it, so that each
  // body takes its own preconditioner from the options (-fieldsplit_artery_pc_type gamg,
  // -fieldsplit_balloon_pc_type lu, ...): the bodies are coupled only by the contact penalty, and an
  // algebraic multigrid that serves the artery's tet10 wall is slowed by the balloon's thin,
  // strongly anisotropic membrane (docs/performance.md). Each split carries its own rigid-body near
  // null space (PCFIELDSPLIT hands an IS's "nearnullspace" to its block).
  const std::vector<std::string> parts = part_names(mesh_);
  std::vector<int> node_part(mesh_.X.size(), 0);  // a node in no element: the first part's split
  for (const auto& el : mesh_.elements) {
    const int k = int(std::find(parts.begin(), parts.end(), mesh_.blocks[el.block].part) - parts.begin());
    for (int a = 0; a < el.nn(); ++a) node_part[el.n[a]] = k;
  }
  for (int k = 0; k < int(parts.size()); ++k) {
    std::vector<PetscInt> nodes;
    for (int i = node_begin_; i < node_end_; ++i)
      if (node_part[iperm_[i]] == k) nodes.push_back(i);
    IS is;
    ANGIO_PETSC(ISCreateBlock(comm_, 3, PetscInt(nodes.size()), nodes.data(), PETSC_COPY_VALUES, &is));
    MatNullSpace nsp = rigid_body_modes_(nodes);
    ANGIO_PETSC(PetscObjectCompose((PetscObject)is, "nearnullspace", (PetscObject)nsp));
    ANGIO_PETSC(PCFieldSplitSetIS(pc, parts[k].c_str(), is));
    MatNullSpaceDestroy(&nsp);
    ISDestroy(&is);
  }
}

std::vector<Face> SolidModel::owned_faces_(const std::string& name, const char* what) {
  const SurfaceSet* s = mesh_.surface(name);
  if (!s) throw std::runtime_error(std::string(what) + ": unknown surface set '" + name + "'");
  std::vector<Face> faces;
  std::vector<int> nodes;  // a face's element may be another rank's: its other nodes are held too
  for (const auto& f : s->faces)
    if (node_owner_[f.n[0]] == rank_) {
      faces.push_back(f);
      nodes.insert(nodes.end(), f.n.begin(), f.n.begin() + f.nn());
    }
  hold_nodes(nodes);
  return faces;
}

void SolidModel::add_pressure(PressureLoad load) {
  pressure_faces_.push_back(owned_faces_(load.surface, "pressure"));
  pressures_.push_back(std::move(load));
}

void SolidModel::add_springs(SpringSupport springs) {
  spring_faces_.push_back(owned_faces_(springs.surface, "springs"));
  springs_.push_back(std::move(springs));
}

void SolidModel::add_dirichlet(DirichletBC bc) {
  for (int n : bc.nodes) {
    if (n < 0 || n >= int(mesh_.X.size())) throw std::runtime_error("dirichlet: node index out of range");
    const int p = perm_[n];
    if (p >= node_begin_ && p < node_end_) dirichlet_rows_.push_back(3 * p + bc.component);
  }
  std::sort(dirichlet_rows_.begin(), dirichlet_rows_.end());
  dirichlet_rows_.erase(std::unique(dirichlet_rows_.begin(), dirichlet_rows_.end()), dirichlet_rows_.end());
  dirichlet_.push_back(std::move(bc));
}

void SolidModel::apply_dirichlet_values_() {
  for (const auto& bc : dirichlet_)
    for (int n : bc.nodes)
      if (holds(n)) u_[ldof_(n, bc.component)] = bc.value(mesh_.X[n], time_);
}

void SolidModel::create_scatter_() {
  if (full_) VecDestroy(&full_);
  if (scatter_) VecScatterDestroy(&scatter_);
  IS is;
  ANGIO_PETSC(ISCreateBlock(PETSC_COMM_SELF, 3, PetscInt(held_.size()), held_.data(), PETSC_COPY_VALUES, &is));
  ANGIO_PETSC(VecCreateSeq(PETSC_COMM_SELF, 3 * PetscInt(held_.size()), &full_));
  ANGIO_PETSC(VecScatterCreate(du_, is, full_, nullptr, &scatter_));
  ISDestroy(&is);
}

void SolidModel::hold_nodes(const std::vector<int>& nodes) {
  const size_t before = held_.size();
  for (int n : nodes) {
    if (n < 0 || n >= int(mesh_.X.size())) throw std::out_of_range("hold_nodes: node index out of range");
    if (slot_[n] >= 0) continue;
    slot_[n] = int(held_.size());
    held_.push_back(perm_[n]);
  }
  int grew = held_.size() > before, any = 0;
  MPI_Allreduce(&grew, &any, 1, MPI_INT, MPI_MAX, comm_);
  if (!any || !du_) return;  // before setup_petsc_: the scatter is created there
  create_scatter_();
  // the new nodes' displacement from their owners: each held state through a global vector
  Vec g;
  ANGIO_PETSC(VecDuplicate(du_, &g));
  std::vector<double> all;
  for (std::vector<double>* v : {&u_, &u_committed_, &u_before_}) {
    int has = v->size() == 3 * before, every = 0;  // u_before_ may be empty (on every rank alike)
    MPI_Allreduce(&has, &every, 1, MPI_INT, MPI_MIN, comm_);
    if (!every) continue;
    PetscScalar* a;
    ANGIO_PETSC(VecGetArray(g, &a));
    std::copy(v->begin(), v->begin() + 3 * (node_end_ - node_begin_), a);
    ANGIO_PETSC(VecRestoreArray(g, &a));
    gather_(g, all);
    v->resize(all.size());
    std::copy(all.begin() + long(3 * before), all.end(), v->begin() + long(3 * before));
  }
  VecDestroy(&g);
}

void SolidModel::restore_state(const std::vector<double>& u) {
  if (u.size() != u_.size()) throw std::logic_error("restore_state: a state of other held nodes");
  u_ = u;
}

Vec3d SolidModel::held_entry_(const std::vector<double>& v, int node) const {
  if (slot_[node] < 0)
    throw std::out_of_range("solid model: rank " + std::to_string(rank_) + " does not hold node " +
                            std::to_string(node));
  const int p = ldof_(node, 0);
  return Vec3d(v[p], v[p + 1], v[p + 2]);
}

Vec3d SolidModel::displacement(int node) const { return held_entry_(u_, node); }

void SolidModel::set_displacement(const std::vector<Vec3d>& u) {
  for (size_t n = 0; n < mesh_.X.size(); ++n)
    if (holds(int(n)))
      for (int k = 0; k < 3; ++k) u_[ldof_(int(n), k)] = u[n](k);
}

std::vector<Vec3d> SolidModel::gather_displacement() const {
  // the owned nodes' entries (the first 3 (node_end_ - node_begin_) of u_) in new numbering
  const int mine = 3 * (node_end_ - node_begin_);
  std::vector<int> counts(size_), offsets(size_ + 1, 0);
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (int r = 0; r < size_; ++r) offsets[r + 1] = offsets[r] + counts[r];
  std::vector<double> whole(offsets[size_]);
  MPI_Allgatherv(u_.data(), mine, MPI_DOUBLE, whole.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm_);
  std::vector<Vec3d> out(mesh_.X.size());
  for (size_t n = 0; n < out.size(); ++n)
    for (int k = 0; k < 3; ++k) out[n](k) = whole[3 * size_t(perm_[n]) + k];
  return out;
}

SolidModel::ViscousState SolidModel::viscous_state(size_t i) {
  if (visc_offset_[i] < 0) return {};
  const auto& el = mesh_.elements[local_elements_[i]];
  return {int(volume_rule(el.type).size()), visc_Q_.data() + visc_offset_[i], visc_S_.data() + visc_offset_[i]};
}

void SolidModel::start_from_held(double t, std::vector<double> u, std::vector<double> u_before, double before_time) {
  if (u.size() != u_.size() || (!u_before.empty() && u_before.size() != u_.size()))
    throw std::logic_error("start_from_held: not a state of the held nodes");
  u_ = std::move(u);
  time_ = committed_time_ = t;
  apply_dirichlet_values_();
  u_committed_ = u_;
  u_before_ = std::move(u_before);
  if (!u_before_.empty()) before_time_ = before_time;
  pc_current_ = false;
}

void SolidModel::start_from(double t, const std::vector<Vec3d>& u, const std::vector<Vec3d>& u_before,
                            double before_time) {
  std::vector<double> held(u_.size()), held_before(u_before.empty() ? 0 : u_.size());
  for (size_t n = 0; n < mesh_.X.size(); ++n)
    if (holds(int(n)))
      for (int k = 0; k < 3; ++k) {
        held[ldof_(int(n), k)] = u[n](k);
        if (!u_before.empty()) held_before[ldof_(int(n), k)] = u_before[n](k);
      }
  start_from_held(t, std::move(held), std::move(held_before), before_time);
}

void SolidModel::gather_(Vec v, std::vector<double>& held) const {
  ANGIO_PETSC(VecScatterBegin(scatter_, v, full_, INSERT_VALUES, SCATTER_FORWARD));
  ANGIO_PETSC(VecScatterEnd(scatter_, v, full_, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar* a;
  PetscInt n;
  ANGIO_PETSC(VecGetLocalSize(full_, &n));
  ANGIO_PETSC(VecGetArrayRead(full_, &a));
  held.assign(a, a + n);
  ANGIO_PETSC(VecRestoreArrayRead(full_, &a));
}

bool SolidModel::assemble(Vec r, Mat K) {
  if (contact_) {
    const double tc = MPI_Wtime();
    const std::vector<NodeCoupling> needed = contact_->prepare(*this, K != nullptr);
    if (K && K == K_ && grow_pattern_(needed)) K = K_;
    contact_seconds_ += MPI_Wtime() - tc;
  }
  ANGIO_PETSC(VecSet(r, 0.0));
  if (K) ANGIO_PETSC(MatZeroEntries(K));
  int ok = 1;
  Eigen::MatrixXd X, u, Ke;
  Eigen::VectorXd fe;
  std::vector<PetscInt> idx;
  auto gather_nodes = [&](const int* n, int nn, bool deformed) {
    X.resize(nn, 3);
    u.resize(nn, 3);
    idx.resize(3 * nn);
    for (int a = 0; a < nn; ++a) {
      const int p = 3 * perm_[n[a]], l = 3 * slot_[n[a]];
      for (int k = 0; k < 3; ++k) {
        X(a, k) = mesh_.X[n[a]](k);
        u(a, k) = u_[l + k];
        idx[3 * a + k] = p + k;
      }
    }
    if (deformed) X += u;
  };
  // the element tangents go straight into K_'s arrays where it has slots for them (MatrixSlots)
  const bool direct = K && slots_.begin(K);
  // fe and Ke of local element `element` (its index in local_elements_), or of a face (-1)
  auto add = [&](int nn, long element = -1) {
    const PetscInt m = 3 * nn;
    ANGIO_PETSC(VecSetValues(r, m, idx.data(), fe.data(), ADD_VALUES));
    if (!K) return;
    if (direct && element >= 0)
      slots_.add(size_t(element), Ke, idx);
    else
      ANGIO_PETSC(MatSetValues(K, m, idx.data(), m, idx.data(), Ke.data(), ADD_VALUES));
  };
  ViscousHistory vh;
  int bad = -1;  // an element this rank found invalid
  for (size_t i = 0; i < local_elements_.size(); ++i) {
    const int e = local_elements_[i];
    const auto& el = mesh_.elements[e];
    gather_nodes(el.n.data(), el.nn(), false);
    const auto& mat = materials_[el.block].matrix;
    if (!element_internal(el.type, X, u, mat, fibers_[i], fe, K ? &Ke : nullptr, nullptr, viscous_history_(i, vh))) {
      ok = 0;
      bad = e;
      break;
    }
    add(el.nn(), long(i));
  }
  if (direct) slots_.end();
  for (size_t i = 0; i < pressures_.size() && ok; ++i) {
    const double p = pressures_[i].pressure(time_);
    if (p == 0.0) continue;
    for (const auto& f : pressure_faces_[i]) {
      gather_nodes(f.n.data(), f.nn(), true);
      face_pressure(f.type, X, p, fe, K ? &Ke : nullptr);
      add(f.nn());
    }
  }
  for (size_t i = 0; i < springs_.size() && ok; ++i) {
    for (const auto& f : spring_faces_[i]) {
      gather_nodes(f.n.data(), f.nn(), false);
      face_springs(f.type, X, u, springs_[i].stiffness, fe, K ? &Ke : nullptr);
      add(f.nn());
    }
  }
  int all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, comm_);
  if (!all_ok) {  // which element (the largest index of those found), for the failure messages
    MPI_Allreduce(&bad, &invalid_element_, 1, MPI_INT, MPI_MAX, comm_);
    if (invalid_element_ >= 0) {  // its centroid from the rank that holds it
      const auto& el = mesh_.elements[invalid_element_];
      Vec3d c = Vec3d::Zero();
      if (elem_rank_[invalid_element_] == rank_) {
        for (int a = 0; a < el.nn(); ++a) c += position(el.n[a]);
        c /= double(el.nn());
      }
      MPI_Allreduce(c.data(), invalid_at_.data(), 3, MPI_DOUBLE, MPI_SUM, comm_);
    }
  }
  if (all_ok && contact_) {
    const double tc = MPI_Wtime();
    contact_->add(*this, r, K);
    contact_seconds_ += MPI_Wtime() - tc;
  }
  ANGIO_PETSC(VecAssemblyBegin(r));
  ANGIO_PETSC(VecAssemblyEnd(r));
  if (K) {
    ANGIO_PETSC(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
    ANGIO_PETSC(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
  }
  if (damping_diag_) damping_(r, K);
  if (!dirichlet_rows_.empty() && apply_bc_) {
    std::vector<PetscScalar> zeros(dirichlet_rows_.size(), 0.0);
    ANGIO_PETSC(VecSetValues(r, PetscInt(zeros.size()), dirichlet_rows_.data(), zeros.data(), INSERT_VALUES));
  }
  ANGIO_PETSC(VecAssemblyBegin(r));
  ANGIO_PETSC(VecAssemblyEnd(r));
  if (K && apply_bc_)
    ANGIO_PETSC(MatZeroRows(K, PetscInt(dirichlet_rows_.size()), dirichlet_rows_.data(), 1.0, nullptr, nullptr));
  return all_ok != 0;
}

std::string SolidModel::invalid_element() const {
  if (invalid_element_ < 0) return "no element found invalid";
  const auto& el = mesh_.elements[invalid_element_];
  std::ostringstream m;
  m << std::setprecision(4) << "last: element " << invalid_element_ << " of block '" << mesh_.blocks[el.block].name
    << "' at (" << invalid_at_(0) << ", " << invalid_at_(1) << ", " << invalid_at_(2) << ") mm";
  return m.str();
}

void SolidModel::lift_prescribed_increment_(SolveReport& rep) {
  // Prescribed displacement increment: lifted through one linearised solve at the old state
  // (du_D = increment, K_FD du_D moved to the right-hand side), so the first iterate is a
  // consistent predictor instead of a boundary layer of distorted elements.
  std::vector<double> u_target = u_;
  std::swap(u_, u_target);
  apply_dirichlet_values_();
  std::swap(u_, u_target);  // u_target: Dirichlet values at the new time
  int any = 0;
  for (const auto& bc : dirichlet_)
    for (int n : bc.nodes) {
      if (!holds(n)) continue;
      const int d = ldof_(n, bc.component);
      if (u_target[d] != u_[d]) any = 1;
    }
  int any_global = 0;
  MPI_Allreduce(&any, &any_global, 1, MPI_INT, MPI_MAX, comm_);
  if (!any_global) return;
  apply_bc_ = false;
  const double tl = MPI_Wtime();
  const bool lok = assemble(r_, K_);
  apply_bc_ = true;
  rep.assembly_seconds += MPI_Wtime() - tl;
  if (!lok) return;
  std::vector<PetscScalar> inc(dirichlet_rows_.size());
  for (size_t i = 0; i < dirichlet_rows_.size(); ++i) {  // owned rows: held entry = row - 3 node_begin_
    const PetscInt l = dirichlet_rows_[i] - 3 * node_begin_;
    inc[i] = u_target[l] - u_[l];
  }
  ANGIO_PETSC(VecSet(du_, 0.0));
  ANGIO_PETSC(VecSetValues(du_, PetscInt(inc.size()), dirichlet_rows_.data(), inc.data(), INSERT_VALUES));
  ANGIO_PETSC(VecAssemblyBegin(du_));
  ANGIO_PETSC(VecAssemblyEnd(du_));
  ANGIO_PETSC(VecScale(r_, -1.0));
  ANGIO_PETSC(MatZeroRowsColumns(K_, PetscInt(dirichlet_rows_.size()), dirichlet_rows_.data(), 1.0, du_, r_));
  KSPConvergedReason reason;
  ANGIO_PETSC(KSPSetReusePreconditioner(ksp_, PETSC_FALSE));  // the tangent of the lifting itself
  keep_splits_(false);
  {
    OptionsScope scope(options_);
    ANGIO_PETSC(KSPSolve(ksp_, r_, du_));
  }
  ++rep.factorizations;
  pc_current_ = kept_current_ = splits_ready_ = true;
  ANGIO_PETSC(KSPGetConvergedReason(ksp_, &reason));
  if (reason > 0 || reason == KSP_DIVERGED_ITS) {
    std::vector<double> du_full;
    gather_(du_, du_full);
    bool finite = true;
    for (double v : du_full) finite = finite && std::isfinite(v);
    if (finite)
      for (size_t i = 0; i < u_.size(); ++i) u_[i] += du_full[i];
  }
}

bool SolidModel::assemble_iterate_(SolveReport& rep, bool tangent) {
  const double ta = MPI_Wtime();
  const bool aok = assemble(r_, tangent ? K_ : nullptr);
  rep.assembly_seconds += MPI_Wtime() - ta;
  if (tangent) ++rep.tangent_assemblies;
  return aok;
}

SolidModel::NewtonLinearSolve SolidModel::newton_linear_solve_(SolveReport& rep, bool fresh, int it, double res,
                                                               std::vector<double>& du_full) {
  const auto& no = opt_.newton;
  const bool modified = no.modified;
  NewtonLinearSolve out;
  // linear solve K du = -r
  ANGIO_PETSC(VecScale(r_, -1.0));
  double t0 = MPI_Wtime();
  KSPConvergedReason reason;
  PetscInt lits;
  const int lag = no.reuse_preconditioner;
  // reuse_parts: the whole preconditioner is set up with every tangent but for the kept splits
  const bool by_parts = !kept_splits_.empty();
  bool reuse = modified ? !fresh : lag > 0 && (by_parts ? kept_current_ : pc_current_);
  auto linear_solve = [&] {
    ANGIO_PETSC(KSPSetReusePreconditioner(ksp_, reuse && !by_parts ? PETSC_TRUE : PETSC_FALSE));
    if (by_parts) keep_splits_(reuse);
    {
      OptionsScope scope(options_);
      ANGIO_PETSC(KSPSolve(ksp_, r_, du_));
    }
    splits_ready_ = true;
    ANGIO_PETSC(KSPGetConvergedReason(ksp_, &reason));
    ANGIO_PETSC(KSPGetIterationNumber(ksp_, &lits));
    rep.linear_iterations += int(lits);
    if (!reuse) ++rep.factorizations;
  };
  linear_solve();
  if (modified) {
    pc_current_ = reason > 0 || reason == KSP_DIVERGED_ITS;
    if (reuse && reason < 0) {  // the old factorization no longer serves: the current tangent instead
      rep.linear_seconds += MPI_Wtime() - t0;
      out.iterations = lits;
      out.current_tangent = true;
      return out;
    }
  } else {
    if (reuse && reason < 0) {  // the old preconditioner no longer serves: factorize this tangent
      reuse = false;
      linear_solve();
    }
    pc_current_ = !(reuse && lits > lag);  // slow with the old one: the next solve refactorizes
    kept_current_ = pc_current_;
  }
  out.iterations = lits;
  rep.linear_seconds += MPI_Wtime() - t0;
  if (reason < 0 && reason != KSP_DIVERGED_ITS) {
    std::ostringstream m;
    m << "linear solver failed at Newton iteration " << it << ": " << KSPConvergedReasons[reason] << " after " << lits
      << " iterations (residual " << res << ")";
    out.failure = m.str();
    return out;
  }
  gather_(du_, du_full);
  bool finite = true;
  for (double v : du_full) finite = finite && std::isfinite(v);
  if (!finite) out.failure = "linear solve produced NaN/Inf at Newton iteration " + std::to_string(it);
  return out;
}

SolidModel::NewtonLineSearch SolidModel::line_search_(SolveReport& rep, const std::vector<double>& du_full, double res,
                                                      bool stale, int it) {
  const auto& no = opt_.newton;
  u_base_ = u_;  // the iterate the step starts from (a member: no allocation per Newton iteration)
  const std::vector<double>& u_base = u_base_;
  // line search (backtracking on ||r||) on residuals alone: a tangent assembly costs several
  // residual ones (element tangents and matrix insertion), so the exact Newton's tangent is assembled
  // once at the accepted iterate, and not at all where that iterate has converged (solve()). alpha
  // ends as the last trial's step. A step of an old factorization (modified Newton) gets no line search: if it
  // does not reduce ||r||, it is undone and the current tangent factorized instead.
  double alpha = 1.0, best_alpha = 1.0, best_merit = std::numeric_limits<double>::infinity();
  double new_res = 0.0;
  bool accepted = false;
  const int tries = no.line_search && !stale ? no.max_line_search + 1 : 1;
  // energy merit: the slope at the start (r_ holds -r(u_base) here, negated for the linear solve); a
  // direction that is not a descent one (s0 >= 0) falls back to the residual merit
  const double s0 = no.energy_line_search && tries > 1 ? -slope_along_(du_full) : 0.0;
  const bool energy = s0 < 0.0;
  for (int ls = 0;; ++ls, alpha *= 0.5) {
    for (size_t i = 0; i < u_.size(); ++i) u_[i] = u_base[i] + alpha * du_full[i];
    const bool aok = assemble_iterate_(rep, false);
    new_res = aok ? norm2(r_) : std::numeric_limits<double>::infinity();
    if (!std::isfinite(new_res)) new_res = std::numeric_limits<double>::infinity();
    const double merit = !std::isfinite(new_res) ? new_res : energy ? std::abs(slope_along_(du_full)) : new_res;
    if (merit < best_merit) {
      best_merit = merit;
      best_alpha = alpha;
    }
    accepted = energy ? merit <= 0.8 * std::abs(s0)
                      : new_res <= (1.0 - 1e-4 * alpha) * res || (!no.line_search && std::isfinite(new_res));
    if (accepted || ls + 1 >= tries) break;
  }
  NewtonLineSearch out;
  if (stale && !(new_res < res)) {  // the old factorization diverges here: back, and the current tangent
    u_ = u_base;
    out.undone = true;
    return out;
  }
  if (!accepted && !stale) {
    if (!std::isfinite(best_merit)) {
      out.failure = "Newton iteration " + std::to_string(it) +
                    ": every line-search trial gave an invalid configuration (inverted element or NaN; " +
                    invalid_element() + ")";
      return out;
    }
    if (best_alpha != alpha) {  // r_ holds the last trial: back to the best one
      alpha = best_alpha;
      for (size_t i = 0; i < u_.size(); ++i) u_[i] = u_base[i] + alpha * du_full[i];
      assemble_iterate_(rep, false);
      new_res = norm2(r_);
    }
  }
  out.alpha = alpha;
  out.residual = new_res;
  return out;
}

double SolidModel::slope_along_(const std::vector<double>& du_full) {
  const PetscScalar* r;
  ANGIO_PETSC(VecGetArrayRead(r_, &r));
  double local = 0.0;
  for (int i = 0; i < 3 * (node_end_ - node_begin_); ++i) local += du_full[i] * r[i];  // owned: held first
  ANGIO_PETSC(VecRestoreArrayRead(r_, &r));
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return global;
}

void SolidModel::log_newton_iteration_(int it, double res, double alpha, PetscInt lits, bool stale,
                                       const std::vector<double>& du_full) {
  // where the residual is largest: which part of the model keeps Newton from converging; and where
  // the Newton step moves a node farthest (the full step, before the line search's alpha): a step
  // that inverts elements shows where. Each rank over its owned nodes, the largest of all on rank 0.
  PetscReal rmax = 0.0;
  ANGIO_PETSC(VecNorm(r_, NORM_INFINITY, &rmax));
  struct Largest {
    double value = -1.0;
    int node = -1;
    Vec3d x = Vec3d::Zero();
  } r_at, du_at;
  {
    const PetscScalar* a;
    ANGIO_PETSC(VecGetArrayRead(r_, &a));
    for (int i = 0; i < 3 * (node_end_ - node_begin_); ++i)
      if (std::abs(a[i]) == rmax) r_at = {double(rmax), iperm_[node_begin_ + i / 3], Vec3d::Zero()};
    ANGIO_PETSC(VecRestoreArrayRead(r_, &a));
  }
  for (int a = 0; a < node_end_ - node_begin_; ++a) {
    const double d = std::hypot(du_full[3 * a], du_full[3 * a + 1], du_full[3 * a + 2]);
    if (d > du_at.value) du_at = {d, iperm_[node_begin_ + a], Vec3d::Zero()};
  }
  for (Largest* l : {&r_at, &du_at})
    if (l->node >= 0) l->x = position(l->node);
  // rows of (value, node, x, y, z) per rank, the first rank's largest kept
  const double mine[10] = {r_at.value,  double(r_at.node),  r_at.x(0),  r_at.x(1),  r_at.x(2),
                           du_at.value, double(du_at.node), du_at.x(0), du_at.x(1), du_at.x(2)};
  std::vector<double> all(rank_ == 0 ? 10 * size_ : 0);
  MPI_Gather(mine, 10, MPI_DOUBLE, all.data(), 10, MPI_DOUBLE, 0, comm_);
  if (rank_ != 0) return;
  for (int r = 1; r < size_; ++r)
    for (int k : {0, 5})
      if (all[10 * r + k] > all[k]) std::copy(all.begin() + 10 * r + k, all.begin() + 10 * r + k + 5, all.begin() + k);
  std::printf(
      "    newton %2d  |r| = %.3e  alpha = %.3g  ksp its = %d%s  max |r_i| %.2e at node %d (%.3f, %.3f, %.3f)  "
      "max |du| %.2e mm at node %d (%.3f, %.3f, %.3f)\n",
      it + 1, res, alpha, int(lits), stale ? " (old factorization)" : "", double(rmax), int(all[1]), all[2], all[3],
      all[4], std::max(all[5], 0.0), int(all[6]), all[7], all[8], all[9]);
}

SolveReport SolidModel::solve(double loose_atol) {
  SolveReport rep;
  const double t_start = MPI_Wtime();
  const double contact_start = contact_seconds_;
  const auto& no = opt_.newton;
  lift_prescribed_increment_(rep);
  apply_dirichlet_values_();
  auto fail = [&](const std::string& msg) {
    rep.converged = false;
    rep.message = msg;
    rep.total_seconds = MPI_Wtime() - t_start;
    rep.contact_seconds = contact_seconds_ - contact_start;
    return rep;
  };
  auto invalid_at = [&](int it) {
    return "invalid configuration at Newton iteration " + std::to_string(it) + " (" + invalid_element() + ")";
  };
  const bool modified = no.modified;
  const double atol = std::max(no.atol, loose_atol);
  // fresh: K_ holds the tangent at the current iterate (to be factorized); otherwise the modified
  // Newton iterates with the factorization held by the KSP.
  bool fresh = !modified || !pc_current_;
  auto invalid_start = [&] {
    return "invalid configuration at the start of the solve (non-positive Jacobian or NaN; " + invalid_element() + ")";
  };
  // the residual first: a solve that starts converged (a held load, a coupling iteration whose
  // interface did not move) needs no tangent
  if (!assemble_iterate_(rep, false)) return fail(invalid_start());
  double res = norm2(r_);
  if (!std::isfinite(res)) return fail("residual is NaN/Inf at the start of the solve");
  const double res0 = res;
  if (no.verbose && rank_ == 0) std::printf("    newton  0  |r| = %.3e\n", res0);
  auto converged = [&](double r, int it) { return r <= atol || (it > 0 && r <= no.rtol * res0); };
  if (fresh && !converged(res, 0) && !assemble_iterate_(rep, true)) return fail(invalid_start());
  rep.residual_history.push_back(res);
  std::vector<double> du_full;
  // Modified Newton: the old factorization failed or diverged at this iterate; the next iteration
  // factorizes the tangent here (the residual is unchanged, recorded again for the iteration count).
  auto current_tangent = [&] {
    if (!assemble_iterate_(rep, true)) return false;
    fresh = true;
    rep.residual_history.push_back(res);
    return true;
  };
  for (int it = 0;; ++it) {
    rep.iterations = it;
    rep.residual = res;
    if (converged(res, it)) {
      rep.converged = true;
      rep.message = "converged";
      if (damping_diag_) rep.damping_force = damping_(nullptr, nullptr);
      break;
    }
    if (it >= no.max_iterations) {
      std::ostringstream m;
      m << "Newton did not converge in " << no.max_iterations << " iterations (residual " << res << ", initial " << res0
        << ")";
      return fail(m.str());
    }
    const NewtonLinearSolve linear = newton_linear_solve_(rep, fresh, it, res, du_full);
    if (linear.current_tangent) {
      if (!current_tangent()) return fail(invalid_at(it));
      continue;
    }
    if (!linear.failure.empty()) return fail(linear.failure);
    const bool stale = modified && !fresh;  // a step of the old factorization (modified Newton)
    const NewtonLineSearch step = line_search_(rep, du_full, res, stale, it);
    if (step.undone) {  // the current tangent instead
      if (!current_tangent()) return fail(invalid_at(it));
      continue;
    }
    if (!step.failure.empty()) return fail(step.failure);
    // the tangent here for the next iteration (the residual is assembled again with it): exact Newton
    // unless converged; modified Newton where the old factorization contracts too slowly
    fresh = !modified || !(step.residual <= no.max_contraction * res);
    if (fresh && !converged(step.residual, it + 1) && !assemble_iterate_(rep, true)) return fail(invalid_at(it));
    res = step.residual;
    rep.residual_history.push_back(res);
    if (no.verbose) log_newton_iteration_(it, res, step.alpha, linear.iterations, stale, du_full);
  }
  rep.total_seconds = MPI_Wtime() - t_start;
  rep.contact_seconds = contact_seconds_ - contact_start;
  return rep;
}

double SolidModel::damping_(Vec r, Mat K) {
  // f_a = η·V_a·(u_a − u_a,committed)/Δt on the owned dofs, added to r (if given); its tangent η·V_a/Δt
  // on the diagonal of K (if given). Returns the global norm of f.
  // No time since the last commit (an evaluation of the committed state itself, as the coupler's
  // synchronization of a continued run): no rate, no damping force.
  const double dt = time_ - committed_time_;
  if (!(dt > 0.0)) return 0.0;
  const PetscScalar* d;
  PetscScalar *rr = nullptr, *kk = nullptr;
  ANGIO_PETSC(VecGetArrayRead(damping_diag_, &d));
  if (r) ANGIO_PETSC(VecGetArray(r, &rr));
  if (K) ANGIO_PETSC(VecGetArray(damping_tangent_, &kk));
  double local = 0.0;
  for (int j = 0; j < 3 * (node_end_ - node_begin_); ++j) {  // owned dofs: the held state's first
    const double f = d[j] * (u_[j] - u_committed_[j]) / dt;
    if (rr) rr[j] += f;
    if (kk) kk[j] = d[j] / dt;
    local += f * f;
  }
  if (r) ANGIO_PETSC(VecRestoreArray(r, &rr));
  if (K) {
    ANGIO_PETSC(VecRestoreArray(damping_tangent_, &kk));
    ANGIO_PETSC(MatDiagonalSet(K, damping_tangent_, ADD_VALUES));
  }
  ANGIO_PETSC(VecRestoreArrayRead(damping_diag_, &d));
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return std::sqrt(global);
}

void SolidModel::element_state_(int e, Eigen::MatrixXd& X, Eigen::MatrixXd& u) const {
  const auto& el = mesh_.elements[e];
  X.resize(el.nn(), 3);
  u.resize(el.nn(), 3);
  for (int a = 0; a < el.nn(); ++a) {
    X.row(a) = mesh_.X[el.n[a]].transpose();
    u.row(a) = displacement(el.n[a]).transpose();
  }
}

void SolidModel::commit() {
  if (!visc_Q_.empty()) {  // advance the viscous history to the current state (Δt from the old commit)
    Eigen::MatrixXd X, u;
    Eigen::VectorXd fe;
    ViscousHistory vh;
    for (size_t i = 0; i < local_elements_.size(); ++i) {
      if (!viscous_history_(i, vh)) continue;
      // in place: each Gauss point reads its committed values before it writes the new ones
      vh.Q_out = visc_Q_.data() + visc_offset_[i];
      vh.S_out = visc_S_.data() + visc_offset_[i];
      const int e = local_elements_[i];
      const auto& el = mesh_.elements[e];
      element_state_(e, X, u);
      element_internal(el.type, X, u, materials_[el.block].matrix, fibers_[i], fe, nullptr, nullptr, &vh);
    }
  }
  if (opt_.newton.extrapolate) {
    if (time_ > committed_time_) {
      u_before_.swap(u_committed_);
      before_time_ = committed_time_;
    } else {
      u_before_.clear();  // start_at: no step to extrapolate along
    }
  }
  u_committed_ = u_;
  committed_time_ = time_;
}
void SolidModel::rollback() {
  u_ = u_committed_;
  pc_current_ = kept_current_ = false;  // a rejected step restarts from a fresh factorization
}

bool SolidModel::predict() {
  if (!opt_.newton.extrapolate) return false;
  u_ = u_committed_;
  if (u_before_.size() != u_.size() || !(committed_time_ > before_time_) || !(time_ > committed_time_)) return false;
  if (!loads_keep_direction(load_levels(before_time_), load_levels(committed_time_), load_levels(time_))) return false;
  if (contact_ && !contact_->extrapolates(committed_time_, time_)) return false;
  const double f = (time_ - committed_time_) / (committed_time_ - before_time_);
  for (size_t i = 0; i < u_.size(); ++i) u_[i] += f * (u_committed_[i] - u_before_[i]);
  apply_dirichlet_values_();               // prescribed values exact at the new time: no lifting solve for them
  if (assemble(r_, nullptr)) return true;  // collective: false on every rank if any element inverted
  u_ = u_committed_;
  return false;
}

std::vector<double> SolidModel::load_levels(double t) const {
  std::vector<double> out;
  for (const auto& p : pressures_) out.push_back(p.pressure(t));
  for (const auto& bc : dirichlet_)
    if (!bc.nodes.empty()) out.push_back(bc.value(mesh_.X[bc.nodes.front()], t));
  if (contact_) contact_->load_levels(t, out);
  return out;
}

void SolidModel::element_stress(std::vector<double>& p1, std::vector<Vec3d>& dir, std::vector<double>* volume,
                                std::vector<Mat3>* gauss) const {
  p1.resize(local_elements_.size());
  dir.resize(local_elements_.size());
  if (volume) volume->resize(local_elements_.size());
  if (gauss) gauss->clear();
  Eigen::MatrixXd X, u;
  Eigen::VectorXd fe;
  for (size_t i = 0; i < local_elements_.size(); ++i) {
    const int e = local_elements_[i];
    const auto& el = mesh_.elements[e];
    element_state_(e, X, u);
    ElementStress es;
    ViscousHistory vh;
    element_internal(el.type, X, u, materials_[el.block].matrix, fibers_[i], fe, nullptr, &es, viscous_history_(i, vh));
    Eigen::SelfAdjointEigenSolver<Mat3> eig(es.cauchy_avg);
    p1[i] = eig.eigenvalues()(2);
    dir[i] = eig.eigenvectors().col(2);
    if (volume) (*volume)[i] = es.volume;
    if (gauss) gauss->insert(gauss->end(), es.cauchy_qp.begin(), es.cauchy_qp.begin() + volume_rule(el.type).size());
  }
}

std::string SolidModel::tangent_response(const std::vector<Vec3d>& f, std::vector<double>& du) {
  if (f.size() != std::size_t(node_end_ - node_begin_))
    throw std::logic_error("tangent_response: forces for another number of owned nodes");
  if (!splits_ready_) return "no tangent factorized yet";
  // r_ and du_ are the Newton's scratch: the next solve assembles r_ again before it reads it
  PetscScalar* a;
  ANGIO_PETSC(VecGetArray(r_, &a));
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int c = 0; c < 3; ++c) a[3 * i + c] = f[i][c];
  for (PetscInt row : dirichlet_rows_) a[row - 3 * node_begin_] = 0.0;
  ANGIO_PETSC(VecRestoreArray(r_, &a));
  ANGIO_PETSC(KSPSetReusePreconditioner(ksp_, PETSC_TRUE));
  if (!kept_splits_.empty()) keep_splits_(true);
  // An iterative solver stops at 1e-2 of the forces here: the Newton–Krylov wants its products to a
  // few per cent (its GMRES tolerance is 0.1 by default), not to the Newton's own linear tolerance.
  // Measured on the generic artery (kept artery split): 1e-4, 1e-3 and 1e-2 give the same 242
  // coupling iterations, the products' solves 23.1 s at 1e-3 and 10.5 s at 1e-2; at 1e-1 their
  // error shows (254 iterations, 333 against 297 products).
  PetscReal rtol, abstol, dtol;
  PetscInt maxits;
  ANGIO_PETSC(KSPGetTolerances(ksp_, &rtol, &abstol, &dtol, &maxits));
  ANGIO_PETSC(KSPSetTolerances(ksp_, std::max(rtol, PetscReal(1e-2)), abstol, dtol, maxits));
  KSPConvergedReason reason;
  {
    OptionsScope scope(options_);
    ANGIO_PETSC(KSPSolve(ksp_, r_, du_));
  }
  ANGIO_PETSC(KSPSetTolerances(ksp_, rtol, abstol, dtol, maxits));
  ANGIO_PETSC(KSPGetConvergedReason(ksp_, &reason));
  if (reason < 0 && reason != KSP_DIVERGED_ITS) return std::string("linear solver: ") + KSPConvergedReasons[reason];
  gather_(du_, du);
  return {};
}

std::vector<Vec3d> SolidModel::contact_forces(ContactModel& c) {
  Vec f;
  ANGIO_PETSC(VecDuplicate(r_, &f));
  ANGIO_PETSC(VecSet(f, 0.0));
  c.prepare(*this, false);  // the contact of this configuration, as an assembly evaluates it
  c.add(*this, f, nullptr);
  ANGIO_PETSC(VecAssemblyBegin(f));
  ANGIO_PETSC(VecAssemblyEnd(f));
  // the owned rows, the owned nodes in order (block size 3)
  std::vector<Vec3d> out(node_end_ - node_begin_);
  const PetscScalar* a;
  ANGIO_PETSC(VecGetArrayRead(f, &a));
  for (size_t i = 0; i < out.size(); ++i) out[i] = -Vec3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]);  // r = f_int − f_ext
  ANGIO_PETSC(VecRestoreArrayRead(f, &a));
  ANGIO_PETSC(VecDestroy(&f));
  return out;
}

}  // namespace angio::solid
