#include "angio/geometry/centerline.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace angio::geometry {

std::vector<Frame> rotation_minimizing_frames(const std::vector<Vec3>& pts) {
  const int n = static_cast<int>(pts.size());
  if (n < 2) throw std::invalid_argument("centerline needs at least 2 points");
  std::vector<Vec3> t(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 a = pts[std::max(i - 1, 0)], b = pts[std::min(i + 1, n - 1)];
    t[i] = (b - a).normalized();
  }
  std::vector<Frame> F(n);
  Vec3 r0 = Vec3::UnitX();
  if (std::abs(r0.dot(t[0])) > 0.9) r0 = Vec3::UnitY();
  r0 = (r0 - r0.dot(t[0]) * t[0]).normalized();
  F[0] = {t[0], r0, t[0].cross(r0)};
  // Double reflection (Wang et al. 2008, algorithm "DR"): reflect the frame in the bisecting
  // plane of the chord v1, then in the plane that maps the reflected tangent onto t[i+1]. The
  // composition is the rotation with the least twist about the tangent (O(h^4) to the exact RMF).
  for (int i = 0; i + 1 < n; ++i) {
    const Vec3 v1 = pts[i + 1] - pts[i];
    const double c1 = v1.dot(v1);
    const Vec3 rL = F[i].normal1 - (2.0 / c1) * v1.dot(F[i].normal1) * v1;
    const Vec3 tL = t[i] - (2.0 / c1) * v1.dot(t[i]) * v1;
    const Vec3 v2 = t[i + 1] - tL;
    const double c2 = v2.dot(v2);
    Vec3 r = c2 > 1e-30 ? Vec3(rL - (2.0 / c2) * v2.dot(rL) * v2) : rL;
    r = (r - r.dot(t[i + 1]) * t[i + 1]).normalized();
    F[i + 1] = {t[i + 1], r, t[i + 1].cross(r)};
  }
  return F;
}

Centerline::Centerline(std::vector<Vec3> points) : pts_(std::move(points)) {
  if (pts_.size() < 2) throw std::invalid_argument("centerline needs at least 2 points");
  s_.assign(pts_.size(), 0.0);
  for (size_t i = 1; i < pts_.size(); ++i) {
    const double len = (pts_[i] - pts_[i - 1]).norm();
    if (!(len > 1e-12))
      throw std::invalid_argument("centerline points " + std::to_string(i - 1) + " and " + std::to_string(i) +
                                  " coincide (zero-length segment)");
    s_[i] = s_[i - 1] + len;
  }
  F_ = rotation_minimizing_frames(pts_);
  Q_.reserve(F_.size());
  for (const auto& f : F_) {
    Eigen::Matrix3d R;
    R.col(0) = f.tangent;
    R.col(1) = f.normal1;
    R.col(2) = f.normal2;
    Q_.emplace_back(R);
  }
}

void Centerline::locate(double s, int& i, double& t) const {
  // first segment whose end lies at or beyond s (the last one beyond the far end)
  const int m = static_cast<int>(s_.size());
  i = static_cast<int>(std::lower_bound(s_.begin() + 1, s_.end() - 1, s) - (s_.begin() + 1));
  i = std::clamp(i, 0, m - 2);
  t = (s - s_[i]) / (s_[i + 1] - s_[i]);  // outside [0, 1] only beyond the ends
}

Vec3 Centerline::point(double s) const {
  int i;
  double t;
  locate(s, i, t);
  return pts_[i] + t * (pts_[i + 1] - pts_[i]);
}

Frame Centerline::frame(double s) const {
  int i;
  double t;
  locate(s, i, t);
  const Eigen::Matrix3d R = Q_[i].slerp(std::clamp(t, 0.0, 1.0), Q_[i + 1]).toRotationMatrix();
  return {R.col(0), R.col(1), R.col(2)};
}

Vec3 Centerline::map(double theta, double s, double r) const {
  const Vec3 c = point(s);
  const Frame f = frame(s);
  return c + r * (std::cos(theta) * f.normal1 + std::sin(theta) * f.normal2);
}

Vec3 Centerline::radial(double theta, double s) const {
  const Frame f = frame(s);
  return std::cos(theta) * f.normal1 + std::sin(theta) * f.normal2;
}

double Centerline::normal_offset(const Vec3& x, double s) const { return (x - point(s)).dot(frame(s).tangent); }

Centerline::Closest Centerline::closest(const Vec3& x) const {
  // g(s) = (x − c(s))·t(s) is continuous and, within a distance 1/κ of the axis, decreasing
  // (g' = −1 + (x − c)·t' ); each sign change between neighbouring vertices brackets a root.
  // Beyond the ends c(s) is a straight extension along t, so the root there is explicit.
  const int m = static_cast<int>(pts_.size());
  std::vector<double> g(m);
  for (int i = 0; i < m; ++i) g[i] = (x - pts_[i]).dot(F_[i].tangent);
  std::vector<double> roots;
  if (g[0] < 0) roots.push_back(g[0]);                      // before the start: s = s0 + g0
  if (g[m - 1] > 0) roots.push_back(s_[m - 1] + g[m - 1]);  // beyond the end
  for (int i = 0; i + 1 < m; ++i) {
    if (g[i] == 0) roots.push_back(s_[i]);
    if ((g[i] > 0 && g[i + 1] < 0) || (g[i] < 0 && g[i + 1] > 0)) {
      // bisection: robust and exact to round-off (at most ~60 halvings of one segment)
      double a = s_[i], b = s_[i + 1], ga = g[i];
      for (int it = 0; it < 200 && b - a > 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(b));
           ++it) {
        const double c = 0.5 * (a + b);
        const double gc = normal_offset(x, c);
        if (gc == 0) {
          a = b = c;
          break;
        }
        if ((gc > 0) == (ga > 0)) {
          a = c;
          ga = gc;
        } else {
          b = c;
        }
      }
      roots.push_back(0.5 * (a + b));
    }
  }
  if (g[m - 1] == 0) roots.push_back(s_[m - 1]);
  Closest best;
  best.distance = std::numeric_limits<double>::infinity();
  for (double s : roots) {
    const Vec3 c = point(s);
    const double d = (x - c).norm();
    if (d < best.distance) {
      best.s = s;
      best.distance = d;
      best.foot = c;
    }
  }
  best.frame = frame(best.s);
  // remove the (round-off) tangential part so that radial ⟂ tangent exactly
  Vec3 rv = x - best.foot;
  rv -= rv.dot(best.frame.tangent) * best.frame.tangent;
  best.radial = rv.norm() > 0 ? Vec3(rv.normalized()) : Vec3::Zero();
  return best;
}

std::vector<Vec3> read_centerline_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open centerline file");
  std::vector<Vec3> pts;
  std::string line;
  int ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    const auto h = line.find('#');
    if (h != std::string::npos) line.resize(h);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t') c = ' ';
    std::istringstream is(line);
    double x, y, z;
    if (!(is >> x)) continue;
    if (!(is >> y >> z)) throw std::runtime_error(path + ":" + std::to_string(ln) + ": expected three numbers x y z");
    pts.emplace_back(x, y, z);
  }
  if (pts.size() < 2) throw std::runtime_error(path + ": centerline needs at least 2 points");
  return pts;
}

Centerline read_centerline(const std::string& path) {
  auto pts = read_centerline_points(path);
  try {
    return Centerline(std::move(pts));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace angio::geometry
