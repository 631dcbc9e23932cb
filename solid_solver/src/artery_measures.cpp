#include "angio/solid/artery_measures.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace angio::solid {

double weighted_quantile(std::vector<double> values, std::vector<double> weights, double q) {
  if (values.size() != weights.size()) throw std::invalid_argument("weighted_quantile: sizes differ");
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<size_t> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return values[a] < values[b]; });
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  double cum = 0.0;
  for (size_t i : order) {
    cum += weights[i];
    if (cum >= q * total * (1.0 - 1e-12)) return values[i];
  }
  return values[order.back()];
}

LumenProfile::LumenProfile(const std::vector<double>& station, int max_stations) {
  nodes_ = station.size();
  if (station.empty()) return;
  const auto [lo, hi] = std::minmax_element(station.begin(), station.end());
  const double smin = *lo, smax = *hi, tol = 1e-6 * std::max(1.0, smax - smin);
  std::vector<double> distinct(station);
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end(), [&](double a, double b) { return b - a <= tol; }),
                 distinct.end());
  const bool rings = int(distinct.size()) <= max_stations;
  // Unstructured mesh (e.g. a tet10 patient artery): a station's diameter is 2 × the mean distance
  // of its nodes from their centroid, which is biased low when a few nodes cover only part of the
  // circumference. Bins hold kMinNodes nodes on average, and sparse ones are dropped below.
  constexpr int kMinNodes = 24;
  const int n = rings ? int(distinct.size()) : std::max(1, std::min(max_stations, int(station.size()) / kMinNodes));
  groups_.assign(n, {});
  std::vector<double> sum(n, 0.0);
  for (size_t i = 0; i < station.size(); ++i) {
    int k;
    if (rings) {
      k = int(std::lower_bound(distinct.begin(), distinct.end(), station[i] - tol) - distinct.begin());
    } else {
      k = std::min(n - 1, int((station[i] - smin) / (smax - smin) * n));
    }
    groups_[k].push_back(int(i));
    sum[k] += station[i];
  }
  // an empty bin, or (unstructured) one with too few nodes to go around the lumen, is no station
  const size_t min_nodes = rings ? 1 : kMinNodes / 3;
  for (int k = 0; k < n; ++k)
    if (groups_[k].size() >= min_nodes) s_.push_back(sum[k] / double(groups_[k].size()));
  groups_.erase(std::remove_if(groups_.begin(), groups_.end(), [&](const auto& g) { return g.size() < min_nodes; }),
                groups_.end());
}

std::vector<double> LumenProfile::diameters(const std::vector<Vec3d>& x, std::vector<Vec3d>* centroids) const {
  if (x.size() != nodes_) throw std::invalid_argument("LumenProfile::diameters: a position per lumen node expected");
  const size_t m = groups_.size();
  std::vector<Vec3d> c(m, Vec3d::Zero());
  for (size_t k = 0; k < m; ++k) {
    for (int n : groups_[k]) c[k] += x[n];
    c[k] /= double(groups_[k].size());
  }
  // Distances are taken in the station's cross-section: normal to the local lumen axis through the
  // neighbouring centroids (current configuration, so a bending vessel is followed). The nodes of
  // an unstructured station spread along the axis and would otherwise count that spread as radius.
  std::vector<double> d(m, 0.0);
  for (size_t k = 0; k < m; ++k) {
    Vec3d t = m > 1 ? Vec3d(c[std::min(k + 1, m - 1)] - c[k > 0 ? k - 1 : 0]) : Vec3d::Zero();
    const double tn = t.norm();
    t = tn > 0 ? Vec3d(t / tn) : Vec3d::Zero();
    double r = 0.0;
    for (int n : groups_[k]) {
      const Vec3d v = x[n] - c[k];
      r += (v - v.dot(t) * t).norm();
    }
    d[k] = 2.0 * r / double(groups_[k].size());
  }
  if (centroids) *centroids = std::move(c);
  return d;
}

Apposition apposition(const std::vector<double>& gap, const std::vector<double>& weight, double threshold) {
  if (gap.size() != weight.size()) throw std::invalid_argument("apposition: sizes differ");
  Apposition a;
  double finite_len = 0.0, gap_sum = 0.0;
  for (size_t i = 0; i < gap.size(); ++i) {
    a.length += weight[i];
    if (!(gap[i] <= threshold)) a.malapposed_length += weight[i];  // also +∞: no wall in range
    if (std::isfinite(gap[i])) {
      finite_len += weight[i];
      gap_sum += weight[i] * gap[i];
      a.max_gap = std::max(a.max_gap, gap[i]);
    }
  }
  a.malapposed_fraction = a.length > 0 ? a.malapposed_length / a.length : 0.0;
  a.mean_gap = finite_len > 0 ? gap_sum / finite_len : std::numeric_limits<double>::quiet_NaN();
  return a;
}

std::vector<double> nodal_areas(const Mesh& mesh, const SurfaceSet& surface) {
  std::vector<double> area(mesh.X.size(), 0.0);
  Eigen::MatrixXd X;
  for (const auto& f : surface.faces) {
    X.resize(f.nn(), 3);
    for (int a = 0; a < f.nn(); ++a) X.row(a) = mesh.X[f.n[a]].transpose();
    const double A = face_area_vector(f.type, X).norm();
    for (int a = 0; a < f.nn(); ++a) area[f.n[a]] += A / f.nn();
  }
  return area;
}

}  // namespace angio::solid
