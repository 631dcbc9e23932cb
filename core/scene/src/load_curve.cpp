#include "angio/scene/load_curve.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace angio::scene {

LoadCurve::LoadCurve(std::vector<std::pair<double, double>> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("LoadCurve: no points");
  for (std::size_t i = 1; i < points_.size(); ++i)
    if (!(points_[i].first > points_[i - 1].first))
      throw std::invalid_argument("LoadCurve: times must increase strictly");
}

double LoadCurve::value(double t) const {
  if (points_.empty()) return 0.0;
  if (t <= points_.front().first) return points_.front().second;
  if (t >= points_.back().first) return points_.back().second;
  for (std::size_t i = 1; i < points_.size(); ++i) {
    if (t <= points_[i].first) {
      const auto& [t0, v0] = points_[i - 1];
      const auto& [t1, v1] = points_[i];
      return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
    }
  }
  return points_.back().second;
}

LoadCurves load_curves(const Node& root) {
  LoadCurves out;
  auto lc = root.optional("load_curves");
  if (!lc) return out;
  for (const std::string& name : lc->keys()) {
    Node c = lc->child(name);
    const std::string expected = "a list of [t, value] pairs with strictly increasing t";
    if (!c.is_sequence() || c.size() == 0) c.fail(expected);
    std::vector<std::pair<double, double>> pts;
    for (std::size_t i = 0; i < c.size(); ++i) {
      Node p = c.at(i);
      if (!p.is_sequence() || p.size() != 2) p.fail("a pair [t, value]");
      double t = p.at(0).as_number(), v = p.at(1).as_number();
      if (!pts.empty() && !(t > pts.back().first)) p.at(0).fail("a time larger than the previous");
      pts.emplace_back(t, v);
    }
    out.emplace(name, LoadCurve(std::move(pts)));
  }
  return out;
}

LoadCurve curve_ref(const Node& node, const std::string& key, const LoadCurves& curves) {
  if (!node.has(key)) return LoadCurve::constant(1.0);
  Node c = node.child(key);
  std::string name = c.as_string();
  auto it = curves.find(name);
  if (it == curves.end()) {
    std::string known;
    for (const auto& [n, _] : curves) known += (known.empty() ? "'" : ", '") + n + "'";
    c.fail("the name of a curve under load_curves" +
           (known.empty() ? std::string(" (none defined)") : " (" + known + ")"));
  }
  return it->second;
}

ScaledCurve scaled_curve(const Node& parent, const std::string& key, const LoadCurves& curves) {
  const Node n = parent.child(key);
  ScaledCurve s;
  if (n.is_scalar()) {
    s.value = n.as_number();
    return s;
  }
  n.check_keys();
  s.value = n.get<double>("value");
  s.curve = curve_ref(n, "curve", curves);
  return s;
}

void require_start_at(const Node& root, const TimeSettings& time, double state_time, const std::string& state) {
  if (std::abs(time.start - state_time) <= 1e-9 * std::max(1.0, std::abs(state_time))) return;
  std::ostringstream m;
  m << "the state's time " << state_time << " s (" << state << "), where the run continues from";
  const auto t = root.optional("time");
  if (t && t->has("start")) t->child("start").fail(m.str());
  root.fail("time.start (default 0) at " + m.str());
}

TimeSettings time_settings(const Node& root) {
  TimeSettings ts;
  auto t = root.optional("time");
  if (!t) return ts;
  t->check_keys();
  ts.start = t->get<double>("start");
  ts.end = t->get<double>("end");
  if (!(ts.end > ts.start)) t->child("end").fail("a time larger than time.start");
  ts.steps = t->get<int>("steps");  // at most 1e6: more is a typo, not a run
  const double nominal = (ts.end - ts.start) / ts.steps;
  ts.min_step = t->has("min_step") ? t->get<double>("min_step") : nominal / 1024.0;
  ts.max_cuts = t->get<int>("max_cuts");
  if (const auto a = t->optional("adaptive")) {
    a->check_keys();
    ts.max_step = a->get<double>("max_step");
    if (!(ts.max_step > nominal * (1.0 + 1e-12) && ts.max_step <= ts.end - ts.start))
      a->child("max_step")
          .fail("a step larger than the nominal one ((end - start)/steps = " + std::to_string(nominal) +
                " s) and at most end - start");
    ts.easy_iterations = a->get<int>("easy_iterations");
  }
  for (const auto& [name, curve] : load_curves(root))
    for (const auto& [tc, v] : curve.points())
      if (tc > ts.start && tc < ts.end) ts.stops.push_back(tc);
  std::sort(ts.stops.begin(), ts.stops.end());
  ts.stops.erase(std::unique(ts.stops.begin(), ts.stops.end()), ts.stops.end());
  return ts;
}

}  // namespace angio::scene
