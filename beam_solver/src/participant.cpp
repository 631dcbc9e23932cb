#include "angio/beam/participant.hpp"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "angio/beam/axis_bow.hpp"
#include "angio/beam/ring_axis.hpp"
#include "angio/common/clock.hpp"
#include "angio/common/log.hpp"

namespace angio::beam {

BeamSolverParticipant::BeamSolverParticipant(BeamScene scene, const std::string& run_dir)
    : scene_(std::move(scene)), run_dir_(run_dir) {
  if (scene_.initial_state) {
    apply_beam_state(*scene_.model, *scene_.initial_state);
    LOG_INFO("beam: continuing from " << scene_.initial_state->path << " at t = " << scene_.initial_state->time
                                      << " s");
  }
  if (!run_dir_.empty()) {
    out_ = std::make_unique<BeamOutput>(run_dir_ + "/beam");
    out_->write_step(*scene_.model, 0, scene_.time.start);  // reference state
  }
  const BeamModel& m = *scene_.model;
  initial_.diameter = m.diameter(true);
  if (scene_.stent) stent_measures(initial_, true);
  LOG_INFO("beam model: " << m.num_nodes() << " nodes, " << m.num_elements() << " elements, " << m.num_free_dofs()
                          << " free DOFs, " << m.num_sample_points() << " contact sample points, linear solver "
                          << m.newton.linear_solver
                          << (m.residual_form == ResidualForm::petrov_galerkin ? ", Petrov-Galerkin residual" : "")
                          << (scene_.generated_stent ? ", generated stent, diameter " : ", diameter ") << m.diameter()
                          << " mm");
}

BeamSolverParticipant::~BeamSolverParticipant() = default;

void BeamSolverParticipant::stent_measures(StepRecord& r, bool reference) const {
  const BeamModel& m = *scene_.model;
  if (!scene_.stent) return;
  // diameters about the axis of the deformed stent (ring_axis.hpp), the reference axis for one ring
  const std::vector<Vec3>& x = m.positions(reference);
  const std::optional<Axis> rings = ring_centroid_axis(scene_.stent->ring_crowns, x);
  const Axis axis = rings.value_or(m.axis);
  r.diameter = mean_diameter(axis, x);
  r.distal_diameter = mean_diameter(axis, x, scene_.stent->distal_nodes);
  r.central_diameter = mean_diameter(axis, x, scene_.stent->central_nodes);
  // length along the deformed axis: a curved device that moves sideways would seem to lengthen on
  // the fixed reference centerline
  r.length = length_along(axis, x);
  std::vector<Vec3> distal, central;
  std::vector<double> distal_s;  // arc length of the foot on the reference axis: sorts the two ends
  for (int n : scene_.stent->distal_nodes) {
    distal.push_back(x[n]);
    distal_s.push_back(m.axis.project(x[n]).s);
  }
  for (int n : scene_.stent->central_nodes) central.push_back(x[n]);
  const AxisBow b = stent_axis_bow(distal, distal_s, central);
  r.axis_sagitta = b.sagitta;
  r.axis_radius = b.radius;
  if (rings) {  // the halves' bows from the same ring centroids
    const auto halves = stent_half_bows(rings->points);
    for (int h = 0; h < 2; ++h) r.axis_radius_half[h] = halves[h].radius;
  }
}

participant::SamplePoints BeamSolverParticipant::sample_points() const {
  const BeamModel& m = *scene_.model;
  participant::SamplePoints sp;
  const int n = m.num_sample_points();
  sp.x.resize(n);
  sp.w.resize(n);
  sp.radius.resize(n);
  for (int g = 0; g < n; ++g) {
    const Vec3 x = m.sample_position(g);
    sp.x[g] = {x.x(), x.y(), x.z()};
    sp.w[g] = m.sample_weight(g);
    sp.radius[g] = m.sample_radius(g);
  }
  return sp;
}

void BeamSolverParticipant::begin_step(int step, double time) {
  step_ = step;
  time_ = time;
  step_iterations_ = 0;
  step_residual_ = 0;
  step_start_ = Clock::now();
  scene_.model->set_time(time);
  LOG_DEBUG("begin step " << step << " t = " << time);
}

participant::SolveStats BeamSolverParticipant::solve_with_planes(const std::vector<participant::Vec3>& q,
                                                                 const participant::ContactPlanes& planes) {
  BeamModel& m = *scene_.model;
  if (participant::planes_per_point(planes.size(), std::size_t(m.num_sample_points())) == 0 ||
      planes.s.size() != planes.size() || planes.n.size() != planes.size()) {
    participant::SolveStats out;
    out.message = "expected K x " + std::to_string(m.num_sample_points()) + " contact planes, got " +
                  std::to_string(planes.size());
    return out;
  }
  std::vector<BeamModel::SamplePlane> p(planes.size());
  for (size_t g = 0; g < p.size(); ++g) {
    p[g].s = Vec3(planes.s[g][0], planes.s[g][1], planes.s[g][2]);
    p[g].n = Vec3(planes.n[g][0], planes.n[g][1], planes.n[g][2]);
    p[g].eps = planes.eps[g];
    p[g].g0 = planes.g0;
  }
  m.set_sample_planes(std::move(p));  // kept for the step's output; the next solve() clears them
  return solve_loads_(q);
}

participant::SolveStats BeamSolverParticipant::linear_response(const std::vector<double>& shift,
                                                               const std::vector<participant::Vec3>& turn,
                                                               std::vector<participant::Vec3>& dx) {
  BeamModel& m = *scene_.model;
  participant::SolveStats out;
  dx.clear();
  if (m.sample_planes().empty() || shift.size() != m.sample_planes().size() ||
      (!turn.empty() && turn.size() != shift.size())) {
    out.message =
        "a linearized response needs the planes of a solve before it: " + std::to_string(m.sample_planes().size()) +
        " planes, " + std::to_string(shift.size()) + " shifts, " + std::to_string(turn.size()) + " turns";
    return out;
  }
  std::vector<Vec3> t(turn.size());
  for (std::size_t i = 0; i < turn.size(); ++i) t[i] = Vec3(turn[i][0], turn[i][1], turn[i][2]);
  try {
    for (const Vec3& d : m.plane_response(shift, t)) dx.push_back({d.x(), d.y(), d.z()});
  } catch (const std::exception& e) {
    out.message = std::string("beam linearized response at step ") + std::to_string(step_) + ": " + e.what();
    return out;
  }
  out.converged = true;
  return out;
}

participant::SolveStats BeamSolverParticipant::solve(const std::vector<participant::Vec3>& q) {
  scene_.model->set_sample_planes({});
  return solve_loads_(q);
}

participant::SolveStats BeamSolverParticipant::solve_loads_(const std::vector<participant::Vec3>& q) {
  BeamModel& m = *scene_.model;
  participant::SolveStats out;
  if (!q.empty()) {
    if (static_cast<int>(q.size()) != m.num_sample_points()) {
      out.converged = false;
      out.message =
          "expected " + std::to_string(m.num_sample_points()) + " line loads, got " + std::to_string(q.size());
      return out;
    }
    std::vector<Vec3> qq(q.size());
    for (size_t i = 0; i < q.size(); ++i) qq[i] = Vec3(q[i][0], q[i][1], q[i][2]);
    m.set_sample_line_loads(qq);
  } else {
    m.set_sample_line_loads(std::vector<Vec3>(m.num_sample_points(), Vec3::Zero()));
  }
  NewtonStats st = m.solve();
  newton_seconds_ += st.seconds;
  iterations_total_ += st.iterations;
  step_iterations_ += st.iterations;
  step_residual_ = st.residual;
  out.converged = st.converged;
  out.iterations = st.iterations;
  out.residual = st.residual;
  out.residual_history = st.residual_history;
  if (!st.converged) {
    std::ostringstream os;
    os << "beam Newton failed at step " << step_ << ", t = " << time_ << " s: " << st.message;
    out.message = os.str();
  }
  LOG_DEBUG("beam solve step " << step_ << ": " << st.iterations << " iterations, residuals "
                               << log::list(st.residual_history) << ", " << st.seconds << " s");
  return out;
}

void BeamSolverParticipant::end_step(bool accept) {
  BeamModel& m = *scene_.model;
  if (!accept) {
    m.restore();
    LOG_DEBUG("step " << step_ << " rejected, state restored");
    return;
  }
  m.commit();
  ++accepted_;
  double mmax = 0;
  for (int e = 0; e < m.num_elements(); ++e) mmax = std::max(mmax, m.bending_moment_norm(e));
  StepRecord r{step_, time_, m.diameter(), step_iterations_, step_residual_, mmax, seconds_since(step_start_)};
  stent_measures(r, false);
  records_.push_back(r);
  last_written_ = false;
  if (out_ && (accepted_ % std::max(1, scene_.output.every) == 0)) {
    out_->write_step(m, step_, time_);
    last_written_ = true;
    write_state_();
  }
  LOG_INFO("beam step " << step_ << " t = " << time_ << " s: " << r.iterations << " it, |r| = " << std::scientific
                        << std::setprecision(2) << r.residual << std::defaultfloat << ", D = " << std::setprecision(5)
                        << r.diameter << " mm, max |M_b| = " << std::setprecision(4) << mmax << " N mm, "
                        << std::setprecision(3) << r.wall_seconds << " s");
}

void BeamSolverParticipant::write_state_() {
  if (!out_ || !scene_.output.state || state_step_ == accepted_) return;
  state_step_ = accepted_;
  try {  // a state that cannot be written must not stop the run
    write_beam_state(*scene_.model, run_dir_ + "/beam/state.h5", accepted_);
  } catch (const std::exception& e) {
    LOG_WARN("beam: state file not written at step " << accepted_ << ": " << e.what()
                                                     << " (the previous one, if any, is kept)");
  }
}

void BeamSolverParticipant::finish() {
  if (finished_) return;
  finished_ = true;
  BeamModel& m = *scene_.model;
  if (out_) {
    if (!last_written_ && !records_.empty()) out_->write_step(m, records_.back().step, records_.back().time);
    write_state_();
    out_->close();
    const bool complete = !records_.empty() && records_.back().time >= scene_.time.end - 1e-12;
    write_summary(run_dir_ + "/beam/summary.json", m, records_, scene_.generated_stent,
                  complete ? "completed" : "incomplete", newton_seconds_, iterations_total_, initial_);
    LOG_INFO("beam output written to " << run_dir_ << "/beam (beam.xdmf, beam.h5, summary.json)");
  }
}

}  // namespace angio::beam
