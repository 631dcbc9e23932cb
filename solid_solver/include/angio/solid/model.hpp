// Distributed quasi-static total-Lagrangian solid model (PETSc + MPI).
//
// Every rank holds the whole (reference) mesh. Elements are partitioned (a PETSc MatPartitioning of
// the element dual graph, or contiguous blocks); each node is owned by the lowest rank among
// its elements and nodes are renumbered so that every rank owns one contiguous block of DOFs
// (3 per node, interlaced). Each rank assembles its own elements into an MPIAIJ matrix
// (block size 3, preallocated) and a residual vector. Each rank holds the displacement of its owned
// nodes, of the other nodes of its elements and faces, and of the nodes a contact model or a
// measure reads on every rank (hold_nodes: the contact surfaces, the lumen, the balloon's rings);
// each Newton update scatters the increment to those nodes only.
#pragma once
#include <mpi.h>
#include <petscksp.h>

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "angio/solid/matrix_slots.hpp"
#include "angio/solid/mesh.hpp"
#include "angio/scene/keys_generated.hpp"
#include "angio/solid/viscous.hpp"

namespace angio::solid {

class SolidModel;

// Hook for contact (stent line-to-surface, balloon-artery surface-to-surface; stent_contact.hpp).
// Called collectively from every assembly with the current configuration; implementations add
// their residual (r = f_int - f_ext convention) and, if K is non-null, tangent contributions with
// VecSetValues/MatSetValues(ADD_VALUES) using model.dof(node, component) global indices.
// Node couplings a contact model's tangent may add beyond the elements': every node of `rows` with
// every node of `cols` (original node numbering).
struct NodeCoupling {
  std::vector<int> rows, cols;
};

class ContactModel {
 public:
  virtual ~ContactModel() = default;
  virtual void add(const SolidModel& model, Vec r, Mat K) = 0;
  // The couplings its tangent can ever need outside the elements' pattern, known from the topology
  // (e.g. the rings of averaged nodal normals); the model makes them part of the matrix's pattern from
  // the start. An entry outside the pattern makes PETSc's AIJ matrix reallocate and copy itself on
  // insertion: measured at 85 % of the solid's time in the patient-like scene's first contact steps.
  virtual std::vector<NodeCoupling> couplings(const SolidModel&) const { return {}; }
  // The nodes (original numbering) whose current positions it reads on every rank, e.g. its
  // surfaces' for their search: the model holds them (SolidModel::hold_nodes) from set_contact() on.
  virtual std::vector<int> held_nodes(const SolidModel&) const { return {}; }
  // Called collectively by every assembly before add(), with the same configuration: a model whose pairs
  // depend on where the surfaces are (balloon-artery Gauss points and the master faces they project
  // onto) evaluates them here and returns the couplings of the pairs it has not returned before; the
  // solid grows its matrix's pattern by those of them it lacks, once, before anything is inserted
  // (one rebuild instead of one reallocation of the matrix per new row), and add() then inserts what
  // was evaluated here. The model calls add() only right after prepare() at the same configuration.
  virtual std::vector<NodeCoupling> prepare(const SolidModel&, bool /*tangent*/) { return {}; }
  // Appends the scalar levels its loading follows at pseudo-time t (a tool's radius; 1 or 0 for a pair
  // switched on at a time): the model extrapolates a step's first iterate only while every load level
  // keeps its direction (load_direction.hpp).
  virtual void load_levels(double /*t*/, std::vector<double>& /*out*/) const {}
  // Whether a step from pseudo-time `from` to `to` may start from the extrapolated state (false: the
  // model starts it from the committed state, as where a load turns).
  virtual bool extrapolates(double /*from*/, double /*to*/) const { return true; }
};

// The scene's solid.newton keys (core/scene/keys.yaml): meaning and defaults there.
struct NewtonOptions {
  int max_iterations = scene::keys::defaults::solid_newton_max_iterations;
  double rtol = scene::keys::defaults::solid_newton_rtol;              // ||r|| <= rtol * ||r_0|| (r_0: first residual)
  double atol = scene::keys::defaults::solid_newton_atol;              // or ||r|| <= atol (N)
  bool line_search = scene::keys::defaults::solid_newton_line_search;  // backtracking on ||r|| (halving)
  int max_line_search = scene::keys::defaults::solid_newton_max_line_search;
  // The line search's merit. residual: ||r|| must decrease (Armijo). energy: the slope of the
  // energy along the step, s(α) = Δu·r(u + αΔu), must fall to |s(α)| <= 0.8 |s(0)| (Matthies &
  // Strang, IJNME 14 (1979) 1613; Wriggers, Nonlinear Finite Element Methods (2008) §5.1.2). Near
  // incompressibility ||r|| is dominated by the volumetric terms, which a full Newton step makes
  // grow at second order even where it minimizes the energy along Δu: the residual merit then cuts
  // the step to 1/16 for a dozen iterations (measured on configs/stability/artery_nearly_incompressible.yaml).
  bool energy_line_search = std::string_view(scene::keys::defaults::solid_newton_line_search_merit) == "energy";
  bool verbose = scene::keys::defaults::solid_newton_verbose;  // per-iteration log on rank 0
  // Artificial viscous damping over the pseudo-time (as Abaqus' *STATIC, STABILIZE): each node gets
  // the force η·V_a·(u_a − u_a,committed)/Δt, V_a its share of the element volumes, Δt the time since
  // the last commit; η in N·s/mm⁴. It carries a load step over a limit point or bifurcation of the
  // pressure-controlled balloon, at the price of an equilibrium error of that size (reported per
  // solve). Being viscous, it depends on the load rate, not on the step: a cut step is damped as
  // strongly per unit rate and its tangent term η·V_a/Δt grows, where a spring toward the committed
  // state would weaken with the shorter increment. 0 = off.
  double damping = scene::keys::defaults::solid_newton_damping;
  // The parts (Block::part, e.g. "balloon") whose elements get the damping; empty: every element. A
  // balloon's unfolding needs it, an artery must not carry its blood pressure by viscosity.
  std::vector<std::string> damping_parts;
  // Lagged preconditioner: > 0 keeps the preconditioner (e.g. the LU factorization of -pc_type lu)
  // of an earlier tangent for later Newton iterations and later solves (coupling iterations, steps)
  // while the Krylov solver (e.g. GMRES) needs at most this many iterations with it; past that, or
  // if it fails, the current tangent is factorized again. A factorization costs a few times as much
  // as an assembly (34k DOFs: 0.7 s against 0.25 s), GMRES iterations with an old factor a fraction
  // of that. The Newton iteration itself keeps the exact tangent (quadratic convergence as long as
  // the Krylov tolerance is tight). 0 = refactorize at every iteration.
  int reuse_preconditioner = scene::keys::defaults::solid_newton_reuse_preconditioner;
  // With -pc_type fieldsplit (one split per part) and reuse_preconditioner > 0: the parts whose
  // split keeps its preconditioner as above; the other splits are set up again with every tangent.
  // A balloon unfolding under pressure changes its tangent at every iteration while the artery's
  // changes slowly: a fresh factorization of the small balloon split and an old one of the large
  // artery split (kept also when contact grows the matrix's pattern: it still preconditions the new
  // one). Empty: the whole preconditioner is kept or renewed together.
  std::vector<std::string> reuse_parts;
  // Modified Newton (tangent: modified): the factorization of an earlier tangent is kept across Newton
  // iterations, solves (coupling iterations) and steps as long as each iteration reduces ||r|| by at
  // least the factor max_contraction; iterations with it assemble the residual only (no element
  // tangents, no matrix insertion, no factorization). A slower iteration has the current tangent
  // assembled and factorized for the next one; one that does not reduce ||r|| at all is undone and
  // repeated with the current tangent. Linear convergence instead of quadratic, at a fraction of the
  // cost per iteration: pays off where the factorization dominates and the tangent changes slowly
  // between solves (the solid in a coupling loop). Exact Newton (false) factorizes every iteration.
  bool modified = std::string_view(scene::keys::defaults::solid_newton_tangent) == "modified";
  double max_contraction = scene::keys::defaults::solid_newton_max_contraction;
  // Continuation of a failed solve: if Newton fails from the last converged state of the step (or
  // the committed one), the change since that state (pseudo-time with its pressures, prescribed
  // displacements, viscous and damping increments, and the stent's sample points) is applied in
  // sub-increments, halved on failure down to 1/continuation of it and grown again after
  // successes. Only the last sub-increment's equilibrium is kept: the result is that of the one
  // full solve, reached from closer starting points (a homotopy in the load, as the load-step cut
  // of the coupler, without repeating the coupling iterations of the step). 0 = off. Default 4
  // (λ = ½ and 1, one halving): every solve carried in the generic artery needed at most one
  // halving, and a hopeless step (a stent inside the wall) pays at most two extra solves per cut.
  int continuation = scene::keys::defaults::solid_newton_continuation;
  // First iterate of a load step: the committed state (false), or the committed state moved on by the
  // last step's motion scaled to this step's increment, u_n + (Δt/Δt_prev)(u_n − u_n−1) (true; a
  // linear extrapolation in the pseudo-time, as the coupler's `prediction: extrapolate` for the
  // interface). A steadily unfolding balloon starts each step close to its end instead of a whole
  // increment away; a predicted state with an inverted element falls back to the committed one.
  // Off by default: it saves 11 % of the straight free expansion's Newton iterations, but in the
  // generic artery's indentation phase, where Newton is limited by the stiffening wall at the stent
  // ends rather than by the distance from the start, it cost a cut step (solid_solver/README.md).
  bool extrapolate = std::string_view(scene::keys::defaults::solid_newton_prediction) == "extrapolate";
};

struct ModelOptions {
  // a MatPartitioning type of the element dual graph (ptscotch, average, square) or "contiguous" index blocks
  std::string partitioner = scene::keys::defaults::solid_partitioner;
  std::string petsc_options;  // appended after the defaults (GMRES(200) + block-Jacobi ILU(1))
  NewtonOptions newton;
  Axis axis;  // fiber frames if the mesh has none
};

struct SolveReport {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;
  std::vector<double> residual_history;
  std::string message;
  int linear_iterations = 0;
  int factorizations = 0;         // preconditioner setups (LU factorizations with -pc_type lu)
  int tangent_assemblies = 0;     // assemblies with the tangent (the others: residual only, modified Newton)
  double assembly_seconds = 0.0;  // elements, loads and contact
  double contact_seconds = 0.0;   // of which contact
  double linear_seconds = 0.0;
  double total_seconds = 0.0;
  double damping_force = 0.0;  // norm of the damping forces at the end (N)
};

// Sums of SolveReports over a run (the solid's part of the benchmark table, summary.json "timing").
struct SolveTotals {
  long solves = 0, newton_iterations = 0, factorizations = 0, tangent_assemblies = 0, linear_iterations = 0;
  double assembly_seconds = 0.0, contact_seconds = 0.0, linear_seconds = 0.0, total_seconds = 0.0;
  void add(const SolveReport& r) {
    ++solves;
    newton_iterations += r.iterations;
    factorizations += r.factorizations;
    tangent_assemblies += r.tangent_assemblies;
    linear_iterations += r.linear_iterations;
    assembly_seconds += r.assembly_seconds;
    contact_seconds += r.contact_seconds;
    linear_seconds += r.linear_seconds;
    total_seconds += r.total_seconds;
  }
};

struct PressureLoad {
  std::string surface;
  std::function<double(double)> pressure;  // p(t) in MPa, acting against the face normal (outward of the body)
};
struct SpringSupport {
  std::string surface;
  double stiffness = 0.0;  // N/mm^3 (per unit reference area)
};
struct DirichletBC {
  std::vector<int> nodes;
  int component = 0;
  std::function<double(const Vec3d& X, double t)> value;
};

class SolidModel {
 public:
  // block_materials[i] is the material of mesh.blocks[i]. Collective on comm.
  SolidModel(MPI_Comm comm, Mesh mesh, std::vector<LayerMaterial> block_materials, ModelOptions options);
  ~SolidModel();
  SolidModel(const SolidModel&) = delete;
  SolidModel& operator=(const SolidModel&) = delete;

  void add_pressure(PressureLoad load);
  void add_springs(SpringSupport springs);
  void add_dirichlet(DirichletBC bc);
  // Collective: the matrix's pattern is extended by the contact model's couplings().
  void set_contact(ContactModel* contact);

  void set_time(double t) { time_ = t; }
  double time() const { return time_; }
  // Start (or restart) the pseudo-time at t with the current state committed there.
  void start_at(double t) {
    time_ = committed_time_ = t;  // no time passes: the viscous history takes only the instantaneous response
    commit();
  }
  // Newton solve at the current time (collective). Never throws for non-convergence. loose_atol > 0
  // relaxes the absolute tolerance to max(newton.atol, loose_atol) (N) for this solve only: an inexact
  // solve inside a coupling loop whose interface is still far from converged.
  SolveReport solve(double loose_atol = 0.0);
  // Current state becomes the committed state; the viscous history (Q, S∞ per Gauss point) is
  // advanced over Δt = t − t_committed from the committed one.
  void commit();
  void rollback();  // back to the last committed state (displacement; the viscous history is only ever committed)
  // First iterate of the step at the current time (newton.extrapolate; collective): the committed
  // state extrapolated along the last committed step, or the committed state itself where there is
  // no earlier step, a load turns (loads_keep_direction over load_levels()), the contact model
  // declines it (ContactModel::extrapolates) or the extrapolated state is invalid. Returns whether
  // it extrapolated.
  bool predict();
  // The levels the loads follow at pseudo-time t: each pressure, each prescribed displacement's value
  // at its first node, then the contact model's (ContactModel::load_levels).
  std::vector<double> load_levels(double t) const;
  // The displacement this rank holds (hold_nodes' order): a solve's starting point, kept and restored
  // by a continuation within the step (rollback() returns to the committed state instead).
  const std::vector<double>& state() const { return u_; }
  const std::vector<double>& committed_state() const { return u_committed_; }  // the same order
  void restore_state(const std::vector<double>& u);

  // --- the committed state, as state files keep it (state_file.hpp)
  double committed_time() const { return committed_time_; }
  // The committed displacement of a node this rank holds (std::out_of_range otherwise); the commit
  // before it (newton.extrapolate) where has_commit_before() (the same on every rank), at before_time().
  Vec3d committed_displacement(int node) const { return held_entry_(u_committed_, node); }
  bool has_commit_before() const { return u_before_.size() == u_committed_.size(); }
  Vec3d displacement_before(int node) const { return held_entry_(u_before_, node); }
  double before_time() const { return before_time_; }
  // Viscous history of local element i (local_elements() order): its Gauss points' committed Q and
  // Sv (points = 0: no viscous branch). Writable only between steps, before a solve uses it.
  struct ViscousState {
    int points = 0;
    Vec6* Q = nullptr;
    Vec6* Sv = nullptr;
  };
  ViscousState viscous_state(size_t i);
  // Continue from a committed state at time t: u of the held nodes (held_index() order, 3 per node)
  // becomes the committed and current displacement; u_before (empty: none) the commit before it, at
  // before_time. Prescribed values are applied at t. The viscous history is set through viscous_state().
  void start_from_held(double t, std::vector<double> u, std::vector<double> u_before, double before_time);
  // The same from whole-mesh vectors by original node index (tests, small meshes).
  void start_from(double t, const std::vector<Vec3d>& u, const std::vector<Vec3d>& u_before, double before_time);

  // --- access (each rank the displacement of the nodes it holds)
  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  const Mesh& mesh() const { return mesh_; }
  const std::vector<LayerMaterial>& materials() const { return materials_; }
  int num_dofs() const { return 3 * int(mesh_.X.size()); }
  int dof(int node, int comp) const { return 3 * perm_[node] + comp; }
  int new_index(int node) const { return perm_[node]; }
  int old_index(int new_node) const { return iperm_[new_node]; }
  int owned_node_begin() const { return node_begin_; }  // in the new numbering
  int owned_node_end() const { return node_end_; }
  const std::vector<int>& local_elements() const { return local_elements_; }
  const std::vector<int>& element_rank() const { return elem_rank_; }
  // Collective: from now on this rank also holds the displacement of `nodes` (original numbering; any
  // rank may pass any nodes, or none). Between solves only: a state() kept before does not fit after.
  void hold_nodes(const std::vector<int>& nodes);
  bool holds(int node) const { return slot_[node] >= 0; }
  int held_index(int node) const { return slot_[node]; }  // its place among the held nodes (-1: not held)
  int num_held_nodes() const { return int(held_.size()); }
  Vec3d displacement(int node) const;  // of a node this rank holds (std::out_of_range otherwise)
  Vec3d position(int node) const { return mesh_.X[node] + displacement(node); }
  void set_displacement(const std::vector<Vec3d>& u);  // by original node index (same on all ranks)
  // Collective: the current displacement of every node (original index) on every rank, a whole-mesh
  // vector per rank: for tests and checks, not for a solver's loops.
  std::vector<Vec3d> gather_displacement() const;
  // Per local element (order of local_elements()): first principal Cauchy stress (Gauss-point
  // averaged Cauchy tensor) and its unit direction.
  // volume (optional): reference volume of each local element.
  // gauss (optional): the Cauchy tensors at the Gauss points of the local elements, element after
  // element, volume_rule(type).size() each (the input of StressRecovery::recover).
  void element_stress(std::vector<double>& p1, std::vector<Vec3d>& dir, std::vector<double>* volume = nullptr,
                      std::vector<Mat3>* gauss = nullptr) const;
  // Nodal forces that contact model c exerts on the solid at the current state (−its residual
  // contribution) at this rank's owned nodes: entry i for node owned_node_begin() + i (new numbering).
  // Collective.
  std::vector<Vec3d> contact_forces(ContactModel& c);
  // The displacement du (the held nodes, state() order) with K du = f for nodal forces f on the owned nodes
  // (contact_forces() order), prescribed components held: the linear solver as the last solve left it
  // (modified Newton: its last factorization, of the tangent at an earlier iterate). For the
  // interface Newton–Krylov's solid response (docs/design.md §5.5); the state does not change.
  // Collective. Returns an empty message, or why the solve failed.
  std::string tangent_response(const std::vector<Vec3d>& f, std::vector<double>& du);
  // Assemble residual (and tangent) at the current state; for tests. Returns false on invalid state.
  bool assemble(Vec r, Mat K);
  // The element an assemble() last found invalid (non-positive Jacobian or NaN), its block and the
  // centroid of that configuration, for failure messages (same on every rank).
  std::string invalid_element() const;
  Mat matrix() const { return K_; }
  KSP linear_solver() const { return ksp_; }                  // for inspection (its splits, its factorizations)
  int pattern_rebuilds() const { return pattern_rebuilds_; }  // of the matrix by contact pairs new to its pattern
  bool direct_insertion() const { return slots_.ready(K_); }  // element tangents go straight into K_ (MatrixSlots)
  // The options of ModelOptions::petsc_options no solver object has asked for so far (misspelt, or
  // for a split that does not exist).
  std::vector<std::string> unused_petsc_options() const;
  Vec residual_vector() const { return r_; }

 private:
  void partition_();
  void setup_petsc_();
  // (Re)creates K_ with the pattern of the elements plus extra_, every entry of it present (explicit
  // zeros, kept by MatZeroEntries), its near null space and the KSP's operators.
  void create_matrix_();
  // Collective: the couplings each rank's contact needs now (ContactModel::prepare) that the pattern lacks are
  // added to extra_ and K_ is rebuilt with them (true), or nothing changes (false).
  bool grow_pattern_(const std::vector<NodeCoupling>& needed);
  // Rigid-body modes of the given owned nodes (new numbering; a near null space for GAMG).
  MatNullSpace rigid_body_modes_(const std::vector<PetscInt>& nodes) const;
  // PCFIELDSPLIT: one split per mesh part, named after it.
  void set_part_splits_(PC pc);
  void apply_dirichlet_values_();
  // v (a global vector) at the held nodes, in their order (scatter_)
  void gather_(Vec v, std::vector<double>& held) const;
  // (Re)creates scatter_ and full_ for the held nodes (collective).
  void create_scatter_();
  // The held state's entry of a node's component (the node must be held).
  int ldof_(int node, int comp) const { return 3 * slot_[node] + comp; }
  // A node's entry of a held state (u_, u_committed_, u_before_); std::out_of_range where this rank
  // does not hold the node.
  Vec3d held_entry_(const std::vector<double>& v, int node) const;
  // Faces of surface set `name` assembled by this rank (those whose first node it owns); `what` names the load.
  // Their nodes are held (collective).
  std::vector<Face> owned_faces_(const std::string& name, const char* what);

  // --- the steps of solve()'s Newton iteration (collective)
  // What the linear solve leaves one Newton iteration (newton_linear_solve_).
  struct NewtonLinearSolve {
    PetscInt iterations = 0;       // Krylov iterations of the (last) KSPSolve
    bool current_tangent = false;  // modified Newton: the old factorization failed; take the current tangent
    std::string failure;           // non-empty: the solve fails with this message
  };
  // What the line search leaves one Newton iteration (line_search_).
  struct NewtonLineSearch {
    double alpha = 1.0;     // the step taken along du
    double residual = 0.0;  // ||r|| there (r_ assembled there)
    bool undone = false;    // an old factorization's step that did not reduce ||r||: u_ back; take the current tangent
    std::string failure;    // non-empty: the solve fails with this message
  };
  // Lifts a prescribed displacement increment by one linearised solve: Newton starts from a consistent predictor.
  void lift_prescribed_increment_(SolveReport& rep);
  // Residual (and, with `tangent`, the tangent) at the current u_, timed and counted in rep; false for an invalid
  // configuration.
  bool assemble_iterate_(SolveReport& rep, bool tangent);
  // K du = -r with modified Newton's / the lagged preconditioner's factorization reuse; du gathered into du_full.
  NewtonLinearSolve newton_linear_solve_(SolveReport& rep, bool fresh, int it, double res,
                                         std::vector<double>& du_full);
  // Backtracking on ||r|| along du_full (an old factorization's step: none, undone if it fails), to the best trial.
  NewtonLineSearch line_search_(SolveReport& rep, const std::vector<double>& du_full, double res, bool stale, int it);
  // Δu·r over all ranks (r_ as assembled, du_full in the global numbering): the energy's slope along du.
  double slope_along_(const std::vector<double>& du_full);
  // The verbose log line of iteration it (rank 0): where the residual is largest, what keeps Newton from converging.
  void log_newton_iteration_(int it, double res, double alpha, PetscInt lits, bool stale,
                             const std::vector<double>& du_full);

  std::vector<double> u_base_;  // line_search_'s starting iterate
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  Mesh mesh_;
  std::vector<LayerMaterial> materials_;
  ModelOptions opt_;
  std::vector<std::vector<FiberFamily>> fibers_;  // per local element (local_elements_ order)
  std::vector<int> elem_rank_, node_owner_, perm_, iperm_, local_elements_;
  int node_begin_ = 0, node_end_ = 0;
  std::vector<PressureLoad> pressures_;
  std::vector<std::vector<Face>> pressure_faces_;  // per load: the faces this rank assembles
  std::vector<SpringSupport> springs_;
  std::vector<std::vector<Face>> spring_faces_;
  std::vector<DirichletBC> dirichlet_;
  std::vector<PetscInt> dirichlet_rows_;  // owned global rows
  ContactModel* contact_ = nullptr;
  double time_ = 0.0, committed_time_ = 0.0;
  bool apply_bc_ = true;
  // The held nodes in new numbering, owned ones first (node_begin_.. in order, so that owned dof i of
  // a global vector is entry i - 3 node_begin_ of the held state), then the others; slot_ per
  // original node: its place among them, -1 if not held (an int per node of the whole mesh, which
  // every rank holds anyway, docs/design.md §7.2).
  std::vector<PetscInt> held_;
  std::vector<int> slot_;
  std::vector<double> u_, u_committed_;  // the held nodes' displacement (3 per node, held_ order)
  std::vector<double> u_before_;         // the commit before u_committed_ (newton.extrapolate)
  double before_time_ = 0.0;
  MatrixSlots slots_;              // where the local elements' tangents go in K_ (found by create_matrix_)
  Vec damping_diag_ = nullptr;     // η·V_a per owned dof (NewtonOptions::damping); null when off
  Vec damping_tangent_ = nullptr;  // η·V_a/Δt, refilled per assembly (no allocation in Newton)
  double damping_(Vec r, Mat K);
  // Viscous branch (eqs. B.5–B.8): committed history per Gauss point of the local elements whose
  // material has one; visc_offset_[i] indexes local element i's first Gauss point (−1: none).
  std::vector<int> visc_offset_;
  std::vector<Vec6> visc_Q_, visc_S_;
  // Committed history of local element i over the step to the current time, filled into h (nullptr if
  // its material has no viscous branch).
  const ViscousHistory* viscous_history_(size_t i, ViscousHistory& h) const;
  // Reference coordinates and current displacements of element e's nodes (rows).
  void element_state_(int e, Eigen::MatrixXd& X, Eigen::MatrixXd& u) const;
  bool pc_current_ = false;  // the preconditioner holds a setup that may be reused (reuse_preconditioner, modified)
  // NewtonOptions::reuse_parts: the kept splits (indices in part order) and whether their setup may be reused
  std::vector<int> kept_splits_;
  bool kept_current_ = false;
  bool splits_ready_ = false;     // the KSP has been set up once (its splits exist)
  void keep_splits_(bool keep);   // sets the kept splits' reuse flag (after the first setup)
  double contact_seconds_ = 0.0;  // time in contact_->add() over the model's life (SolveReport::contact_seconds)
  int invalid_element_ = -1;      // invalid_element()
  Vec3d invalid_at_ = Vec3d::Zero();
  Mat K_ = nullptr;
  std::vector<NodeCoupling> extra_;             // the couplings K_'s pattern has beyond the elements'
  std::vector<std::vector<PetscInt>> pattern_;  // per owned node: its column nodes in K_ (new numbering, sorted)
  int pattern_rebuilds_ = 0;                    // of K_ by grow_pattern_
  Vec r_ = nullptr, du_ = nullptr;
  KSP ksp_ = nullptr;
  VecScatter scatter_ = nullptr;
  Vec full_ = nullptr;
  PetscOptions options_ = nullptr;
};

const char* petsc_default_options();

}  // namespace angio::solid
