// The solid solver as a participant (balloon + artery), collective over an MPI communicator.
//
// Standalone: every rank calls the SolidParticipant methods (run_standalone on all ranks).
// Coupled: rank 0 talks to the coupler through MpiSolidParticipant, which broadcasts every call
// and its arguments; ranks > 0 run run_follower() and execute the same calls collectively.
#pragma once
#include <mpi.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "angio/participant/solid_participant.hpp"
#include "angio/solid/artery_measures.hpp"
#include "angio/solid/element_stress_summary.hpp"
#include "angio/solid/output.hpp"
#include "angio/solid/scene.hpp"
#include "angio/solid/stress_recovery.hpp"

namespace angio::solid {

// Stent (line-to-surface) contact for the participant (stent_contact.hpp): gets the beam sample points
// before each solve, acts as the model's ContactModel during Newton, and fills the reply afterwards.
class StentContact : public ContactModel {
 public:
  virtual void set_points(const participant::SamplePoints& points) = 0;
  // The contact of the current state for the reply to the beam, complete on rank 0 (the rank that
  // answers the coupler); the other ranks' reply is left as given. Collective.
  virtual void fill_reply(const SolidModel& model, participant::ContactReply& reply) = 0;
  // The stent line contact alone (its points, forces and reply), without contact models that do not
  // depend on the points (a composite's others); nullptr if there is none.
  virtual StentContact* line_part() { return this; }
  // Gap of every sample point of set_points() to the surface set `surface` at the current state
  // (mm, g = (x − s)·n − R; +∞ where no face lies within the search radius), and the points'
  // arc-length weights; both empty if this contact does not involve that surface, and on every rank
  // but 0. Collective.
  virtual void gaps(const SolidModel& model, const std::string& surface, std::vector<double>& gap,
                    std::vector<double>& weight) {
    (void)model, (void)surface;
    gap.clear();
    weight.clear();
  }
};

// A contact-free reply for `points` (zero line loads, surface points = the points, inactive); SolidRunner::solve
// starts every reply with it before the stent contact fills it.
void reset_reply(const participant::SamplePoints& points, participant::ContactReply& reply);

// First principal Cauchy stress of one block (layer) at one step (per element: the eigenvalue of
// the Gauss-point averaged Cauchy tensor): the element measures (element_stress_summary.hpp: where
// the maximum is, p99, the ball-averaged maximum; rank 0 only) and the recovered nodal ones.
// (The maximum itself is StepSummary::max_p1, known on every rank.)
struct BlockStress : ElementStressSummary {
  // The recovered nodal first principal stress of the block (stress_recovery.hpp: L2 projection onto
  // the block's own nodes, a layer interface node has one value per layer), rank 0 only; NaN: none.
  double max_nodal = std::numeric_limits<double>::quiet_NaN();  // max over the block's nodes (MPa)
  Vec3d where_nodal = Vec3d::Zero();                            // current position of that node
  // 99th percentile, each node weighted by its share of the block's reference volume (Σ V_e / n_e)
  double p99_nodal = std::numeric_limits<double>::quiet_NaN();
  // max over the block's nodes on the lumen surface (scene lumen set, the endothelium); NaN if the
  // block does not touch the lumen or the scene has none
  double max_endothelium_nodal = std::numeric_limits<double>::quiet_NaN();
};

// Per committed step summary (written to <run-dir>/solid/summary.json).
struct StepSummary {
  int step = 0;
  double time = 0.0;
  std::vector<std::pair<std::string, double>> pressures;         // label, MPa
  std::vector<double> max_p1;                                    // per block (MPa)
  std::vector<BlockStress> stress;                               // per block
  std::vector<std::pair<std::string, double>> max_displacement;  // per part (mm)
  std::vector<double> lumen_diameter;                            // per lumen station (mm)
  std::vector<Vec3d> lumen_centroid;                             // per lumen station (mm)
  std::vector<std::pair<std::string, double>>
      artery_contact_force;                                 // per contact: Σ |nodal force| on the endothelium (N)
  std::optional<Apposition> apposition;                     // stent vs endothelium
  std::optional<std::pair<double, double>> stent_stations;  // axial extent of the stent on the lumen stations (mm)
  double d_mid = 0.0, d_end0 = 0.0, d_end1 = 0.0;           // balloon outer diameter (mm)
  int newton_iterations = 0;
  double residual = 0.0;
  double solve_seconds = 0.0;
};

class SolidRunner : public participant::SolidParticipant {
 public:
  // Collective. run_dir may be empty (no output). Writes the initial state as step 0.
  SolidRunner(MPI_Comm comm, SolidScene scene, const std::string& run_dir);
  ~SolidRunner() override;

  void begin_step(int step, double time) override;
  participant::SolveStats solve(const participant::SamplePoints& beam_points, participant::ContactReply& reply,
                                double tolerance) override;
  // Collective; the shifts on rank 0 (the other ranks' left empty).
  participant::SolveStats linear_response(const std::vector<participant::Vec3>& dx, std::vector<double>& plane_shift,
                                          std::vector<participant::Vec3>& normal_turn) override;
  void end_step(bool accept) override;
  void finish() override;

  SolidModel& model() { return *model_; }
  const SolidScene& scene() const { return scene_; }  // its mesh was moved into the model: model().mesh()
  // Registers the stent contact (not owned; nullptr: no stent contact, zero line loads).
  void set_stent_contact(StentContact* contact) {
    stent_contact_ = contact;
    model_->set_contact(contact);
  }
  // A contact model whose force on the endothelium is reported per step under `name` (not owned).
  void add_contact_report(const std::string& name, ContactModel* model) { contact_reports_.emplace_back(name, model); }
  void clear_contact_reports() { contact_reports_.clear(); }
  const std::vector<StepSummary>& history() const { return history_; }
  const SolveReport& last_report() const { return last_; }
  const SolveTotals& totals() const { return totals_; }
  // Balloon outer diameters (mm) at mid-length and both ends for the current state (all ranks).
  void balloon_diameters(double& mid, double& end0, double& end1) const;

 private:
  void record_and_write_(int step, double time);
  // summary.json on rank 0 after gathering each rank's peak memory and messages. Collective.
  void write_summary_();
  // per_rank: each rank's peak resident set (KiB), PETSc messages and their bytes and its peak resident set
  // before the first solve (KiB), in rank order.
  void write_summary_json_(const std::vector<double>& per_rank, double matrix_nonzeros) const;
  // <run>/solid/state.h5 (output.state) with the last committed step, unless already written. Collective.
  void write_state_();
  int state_step_ = -1;  // committed step the state file holds

  MPI_Comm comm_;
  int rank_ = 0;
  SolidScene scene_;
  std::string dir_;
  std::unique_ptr<SolidModel> model_;
  std::unique_ptr<FieldWriter> writer_;
  std::unique_ptr<StressRecovery> recovery_;     // recovered nodal stresses per layer
  std::vector<std::string> nodal_stress_names_;  // their output fields, per block
  double recovery_seconds_ = 0.0;                // all recover() calls (rank 0), summary.json timing
  double stress_summary_seconds_ = 0.0;          // all block_stress_ calls (on rank 0): max, p99, ball average
  double reply_seconds_ = 0.0;           // the stent contact's replies and per-step gaps outside the solves (rank 0)
  double state_file_seconds_ = 0.0;      // all state file writes (rank 0's clock), summary.json timing
  long products_ = 0;                    // linear_response calls, summary.json timing
  double product_seconds_ = 0.0;         // all linear_response calls (rank 0's clock)
  double product_linear_seconds_ = 0.0;  // of which the solves with the kept factorization
  bool warned_recovery_ = false;
  std::vector<StepSummary> history_;
  SolveReport last_;
  SolveTotals totals_;        // every solve of the run, rejected steps included
  long setup_peak_kib_ = -1;  // peak resident set before the first solve: mesh, model, matrix, contact built
  int step_ = 0;
  int committed_ = 0;
  double time_ = 0.0;
  bool warned_contact_ = false;
  StentContact* stent_contact_ = nullptr;
  bool finished_ = false;
  std::vector<int> ring_mid_, ring_end0_, ring_end1_;
  // artery outputs (empty without an artery)
  LumenProfile lumen_;
  std::vector<double> endothelium_area_;  // lumped nodal area of artery_inner per owned node (0 off the lumen)
  std::vector<int> lumen_nodes_;          // the lumen profile's nodes (held on every rank)
  std::vector<std::pair<std::string, ContactModel*>> contact_reports_;
  participant::SamplePoints points_;  // beam sample points of the last solve (stent extent, linear_response)
  // linear_response's start: the last solve of this step converged, its reply (complete on rank 0)
  // and the stent contact's forces on this rank's owned nodes there (empty until a response asks)
  bool linearizable_ = false;
  participant::ContactReply linear_reply_;
  std::vector<Vec3d> linear_forces_;
  // The last converged solve of the step (pseudo-time and sample points) and of the last committed
  // step: where a continuation starts from.
  double ok_time_ = 0.0, committed_ok_time_ = 0.0;
  std::vector<participant::Vec3> ok_x_, committed_ok_x_;
  // The step's first iterate was extrapolated (solid.newton.prediction) and no solve of the step has
  // converged yet: a continuation starts from the committed state, the state at ok_time_, not from the
  // prediction made for the step's own time.
  bool predicted_ = false;
  SolveReport continuation_(const participant::SamplePoints& pts, const std::vector<double>& u_start, double tolerance);
  void artery_measures_(StepSummary& s, std::vector<double>& contact_pressure);
  // element_stress_summary.hpp into s.stress (rank 0); collective
  void block_stress_(const std::vector<double>& p1, const std::vector<double>& vol, StepSummary& s) const;
  void nodal_stress_(StepSummary& s) const;  // from recovery_, into s.stress (rank 0)
  void write_apposition_csv_(const std::vector<double>& gap, const std::vector<double>& weight) const;
};

// Rank-0 side of the coupled mode: broadcasts each call to the followers, then runs it.
class MpiSolidParticipant : public participant::SolidParticipant {
 public:
  MpiSolidParticipant(participant::SolidParticipant& inner, MPI_Comm comm) : inner_(inner), comm_(comm) {}
  void begin_step(int step, double time) override;
  participant::SolveStats solve(const participant::SamplePoints& beam_points, participant::ContactReply& reply,
                                double tolerance) override;
  participant::SolveStats linear_response(const std::vector<participant::Vec3>& dx, std::vector<double>& plane_shift,
                                          std::vector<participant::Vec3>& normal_turn) override;
  void end_step(bool accept) override;
  void finish() override;
  // Releases the followers if finish() was never called (e.g. the coupler vanished).
  void shutdown();

 private:
  participant::SolidParticipant& inner_;
  MPI_Comm comm_;
  bool finished_ = false;
};

// Ranks > 0 in the coupled mode: executes broadcast calls until finish. Returns 0.
int run_follower(participant::SolidParticipant& inner, MPI_Comm comm);

}  // namespace angio::solid
