// BeamParticipant implementation: drives a BeamModel for the standalone loop and the coupler.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "angio/beam/output.hpp"
#include "angio/beam/scene.hpp"
#include "angio/participant/beam_participant.hpp"

namespace angio::beam {

class BeamSolverParticipant : public participant::BeamParticipant {
 public:
  // run_dir empty → no output files.
  BeamSolverParticipant(BeamScene scene, const std::string& run_dir);
  ~BeamSolverParticipant() override;

  participant::SamplePoints sample_points() const override;
  void begin_step(int step, double time) override;
  participant::SolveStats solve(const std::vector<participant::Vec3>& line_loads) override;
  participant::SolveStats solve_with_planes(const std::vector<participant::Vec3>& line_loads,
                                            const participant::ContactPlanes& planes) override;
  participant::SolveStats linear_response(const std::vector<double>& plane_shift,
                                          const std::vector<participant::Vec3>& normal_turn,
                                          std::vector<participant::Vec3>& dx) override;
  void end_step(bool accept) override;
  void finish() override;

  BeamModel& model() { return *scene_.model; }
  const std::vector<StepRecord>& records() const { return records_; }

 private:
  BeamScene scene_;
  std::string run_dir_;
  std::unique_ptr<BeamOutput> out_;
  std::vector<StepRecord> records_;
  int step_ = 0, accepted_ = 0;
  double time_ = 0;
  int step_iterations_ = 0;
  double step_residual_ = 0;
  std::chrono::steady_clock::time_point step_start_;
  double newton_seconds_ = 0;
  long iterations_total_ = 0;
  bool finished_ = false;
  bool last_written_ = true;
  StepRecord initial_{};  // stent measures of the reference state
  void stent_measures(StepRecord& r, bool reference) const;
  // <run>/beam/state.h5 (output.state) with the last committed step, unless already written.
  void write_state_();
  int state_step_ = -1;  // committed step the state file holds
  participant::SolveStats solve_loads_(const std::vector<participant::Vec3>& line_loads);
};

}  // namespace angio::beam
