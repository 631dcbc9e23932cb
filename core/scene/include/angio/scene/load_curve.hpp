// Piecewise-linear load curves of pseudo-time, declared once at the top level of a scene:
//   load_curves:
//     pressure: [[0.0, 0.0], [1.0, 1.317], [2.0, 0.0]]   # [t (s), value]
// and referenced by name from loads (e.g. `curve: pressure`). Constant outside the given range.
#pragma once
#include <algorithm>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "angio/scene/node.hpp"

namespace angio::scene {

class LoadCurve {
 public:
  LoadCurve() = default;
  explicit LoadCurve(std::vector<std::pair<double, double>> points);  // strictly increasing t
  static LoadCurve constant(double v) { return LoadCurve({{0.0, v}}); }
  double value(double t) const;
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_;
};

using LoadCurves = std::map<std::string, LoadCurve>;

// Parses the top-level `load_curves:` map (absent → empty).
LoadCurves load_curves(const Node& root);

// Reads `key` of `node` as a curve name and looks it up; the error names the known curves.
// Absent key → constant 1 (a load without a curve is applied fully at every time).
LoadCurve curve_ref(const Node& node, const std::string& key, const LoadCurves& curves);

// A load given as a plain number (constant) or as {value, curve}: value × curve(t).
struct ScaledCurve {
  double value = 0.0;
  LoadCurve curve = LoadCurve::constant(1.0);
  double at(double t) const { return value * curve.value(t); }
  // Smallest and largest value × curve (at the curve's points: piecewise linear, so these are its
  // extremes).
  std::pair<double, double> range() const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& [t, v] : curve.points()) {
      lo = std::min(lo, value * v);
      hi = std::max(hi, value * v);
    }
    return {lo, hi};
  }
};
// Reads `key` of `parent` in either form (the value of {value, curve} defaults to 1).
ScaledCurve scaled_curve(const Node& parent, const std::string& key, const LoadCurves& curves);

// The `time:` section: pseudo-time interval and load steps, shared by all participants.
struct TimeSettings {
  double start = keys::defaults::time_start;
  double end = 1.0;  // end and steps without a `time:` section: one step from 0 to 1
  int steps = 1;
  double min_step = 0.0;  // smallest step the stepper may cut down to (default: initial/1024)
  int max_cuts = keys::defaults::time_max_cuts;
  // Adaptive steps (time.adaptive; off: max_step = 0): after a step that needed at most
  // easy_iterations iterations (coupling iterations, or Newton iterations of a participant alone)
  // the increment doubles, up to max_step; after a harder step it is the nominal one again.
  double max_step = 0.0;
  int easy_iterations = keys::defaults::time_adaptive_easy_iterations;
  // Times no step crosses: the corners of the load curves inside (start, end), sorted. A larger
  // step lands on them (and on the nominal grid), so a peak of a curve is always hit exactly.
  std::vector<double> stops;
};
TimeSettings time_settings(const Node& root);
// A run continued from a state file starts at the state's time: otherwise a SceneError on
// time.start naming the state (`state` describes it, e.g. its path).
void require_start_at(const Node& root, const TimeSettings& time, double state_time, const std::string& state);

}  // namespace angio::scene
