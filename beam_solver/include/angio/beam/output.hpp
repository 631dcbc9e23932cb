// Output of the beam side in <run-dir>/beam/: beam.h5 (one group per committed output step),
// beam.xdmf (ParaView: stent polyline with node and element fields + contact sample points),
// summary.json (final node positions, diameter per step, max/final diameter, recoil).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "angio/beam/model.hpp"

namespace angio::beam {

class BeamOutput {
 public:
  explicit BeamOutput(const std::string& dir);  // creates dir, opens beam.h5
  ~BeamOutput();
  BeamOutput(const BeamOutput&) = delete;
  BeamOutput& operator=(const BeamOutput&) = delete;

  void write_step(const BeamModel& m, int step, double time);
  void close();

 private:
  void write_xdmf() const;
  std::string dir_;
  long file_ = -1;
  struct StepInfo {
    int step;
    double time;
    std::string group;
  };
  std::vector<StepInfo> steps_;
  int nn_ = 0, ne_ = 0, ng_ = 0;
};

struct StepRecord {
  int step;
  double time;
  double diameter;
  int iterations;
  double residual;
  double max_bending_moment;
  double wall_seconds;
  // generated stents only (else NaN): diameters of the outer crowns of the end rings and of
  // the crowns of the middle ring(s), and the stent length along the device axis
  double distal_diameter = std::numeric_limits<double>::quiet_NaN();
  double central_diameter = std::numeric_limits<double>::quiet_NaN();
  double length = std::numeric_limits<double>::quiet_NaN();
  // bow of the device axis through the centroids of the end rings' outer crowns and of the middle
  // crowns (axis_bow.hpp)
  double axis_sagitta = std::numeric_limits<double>::quiet_NaN();
  double axis_radius = std::numeric_limits<double>::quiet_NaN();
  // radius of each half's bow (stent_half_bows: end ring, quarter ring, middle ring)
  double axis_radius_half[2] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

// Writes summary.json (nlohmann::json, indent 2; non-finite numbers as null); returns the text
// written. `initial`: the measures of the reference state (its diameter for every model, the
// stent measures for generated stents).
std::string write_summary(const std::string& path, const BeamModel& m, const std::vector<StepRecord>& steps,
                          bool generated_stent, const std::string& status, double newton_seconds,
                          long newton_iterations, const StepRecord& initial);

}  // namespace angio::beam
