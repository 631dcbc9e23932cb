#include "angio/solid/stress_average.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "angio/contact/search.hpp"

namespace angio::solid {

namespace {

// one box per point, inflated by the radius: the tree over them answers "within the radius along
// every axis" for a query point, the exact distance decides
std::vector<contact::Aabb> inflated_boxes(const std::vector<Vec3d>& x, double radius) {
  std::vector<contact::Aabb> boxes(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    boxes[i].extend(x[i]);
    boxes[i].inflate(radius);
  }
  return boxes;
}

// The sample points in the contact search's AABB tree (inflated_boxes). Both functions below
// evaluate a ball through this one class, so their values agree bit for bit.
class BallSampler {
 public:
  BallSampler(const std::vector<Vec3d>& point, const std::vector<double>& value, const std::vector<double>& weight,
              double radius)
      : point_(point), value_(value), weight_(weight), r2_(radius * radius) {
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw std::invalid_argument("ball average: the radius must be positive and finite");
    if (value.size() != point.size() || weight.size() != point.size())
      throw std::invalid_argument("ball average: points, values and weights differ in number");
    tree_.build(inflated_boxes(point, radius));
  }

  // Σ w_j f_j / Σ w_j over the points within the radius of c; NaN for an empty ball
  double average(const Vec3d& c) {
    near_.clear();
    tree_.query(c, near_);
    double sum = 0.0, w = 0.0;
    for (const int p : near_)
      if (inside(point_[p], c)) {
        sum += weight_[p] * value_[p];
        w += weight_[p];
      }
    return w > 0.0 ? sum / w : std::numeric_limits<double>::quiet_NaN();
  }

  // the one membership test, |x − c|² ≤ r², the same expression from either side
  bool inside(const Vec3d& x, const Vec3d& c) const { return (x - c).squaredNorm() <= r2_; }

 private:
  const std::vector<Vec3d>& point_;
  const std::vector<double>& value_;
  const std::vector<double>& weight_;
  double r2_;
  contact::AabbTree tree_;
  std::vector<int> near_;
};

}  // namespace

std::vector<double> ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                                 const std::vector<double>& value, const std::vector<double>& weight, double radius) {
  BallSampler ball(point, value, weight, radius);
  std::vector<double> out(centre.size(), std::numeric_limits<double>::quiet_NaN());
  if (point.empty()) return out;
  for (std::size_t c = 0; c < centre.size(); ++c) out[c] = ball.average(centre[c]);
  return out;
}

BallMaximum max_ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                             const std::vector<double>& value, const std::vector<double>& weight, double radius) {
  BallSampler ball(point, value, weight, radius);
  BallMaximum best;
  if (point.empty() || centre.empty()) return best;
  // A weighted mean never exceeds the largest value it averages: a ball whose average reaches A holds
  // a point with f ≥ A. Visiting the points by decreasing f and averaging every ball that holds the
  // point visited, the best average A found so far only grows; once the next point's f is below A,
  // every ball not yet averaged holds only points below A and cannot reach it. The balls averaged
  // include every ball whose average is ≥ the final A, so the maximum and its first centre (ties to
  // the lowest index, as a scan of ball_average's field) are exact. The stop keeps a margin of 1e-10 A
  // because a computed mean can exceed its largest value by rounding (of order n·eps for n points).
  contact::AabbTree centres;
  centres.build(inflated_boxes(centre, radius));
  std::vector<int> order;  // the points by decreasing value; a non-finite one makes its balls NaN anyway
  order.reserve(point.size());
  for (std::size_t p = 0; p < point.size(); ++p)
    if (std::isfinite(value[p])) order.push_back(int(p));
  std::sort(order.begin(), order.end(), [&](int a, int b) { return value[a] > value[b]; });
  std::vector<char> done(centre.size(), 0);
  std::vector<int> near;
  for (const int p : order) {
    if (best.centre != BallMaximum::none && value[p] + 1e-10 * std::abs(best.value) < best.value) break;
    near.clear();
    centres.query(point[p], near);  // in the tree's order: ties go to the lowest index below
    for (const int c : near) {
      if (done[c] || !ball.inside(point[p], centre[c])) continue;
      done[c] = 1;
      ++best.balls;
      const double a = ball.average(centre[c]);
      if (!std::isfinite(a)) continue;  // a ball of zero weight, as ball_average's NaN
      if (best.centre == BallMaximum::none || a > best.value || (a == best.value && std::size_t(c) < best.centre)) {
        best.value = a;
        best.centre = std::size_t(c);
      }
    }
  }
  return best;
}

}  // namespace angio::solid
