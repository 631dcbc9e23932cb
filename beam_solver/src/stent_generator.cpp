#include "angio/beam/stent_generator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace angio::beam {

std::vector<std::array<Vec3, 3>> rotation_minimizing_frames(const std::vector<Vec3>& pts) {
  const int n = static_cast<int>(pts.size());
  if (n < 2) throw std::invalid_argument("centerline needs at least 2 points");
  std::vector<Vec3> t(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 a = pts[std::max(i - 1, 0)], b = pts[std::min(i + 1, n - 1)];
    t[i] = (b - a).normalized();
  }
  std::vector<std::array<Vec3, 3>> F(n);
  Vec3 r0 = Vec3::UnitX();
  if (std::abs(r0.dot(t[0])) > 0.9) r0 = Vec3::UnitY();
  r0 = (r0 - r0.dot(t[0]) * t[0]).normalized();
  F[0] = {t[0], r0, t[0].cross(r0)};
  for (int i = 0; i + 1 < n; ++i) {
    const Vec3 v1 = pts[i + 1] - pts[i];
    const double c1 = v1.dot(v1);
    const Vec3 rL = F[i][1] - (2.0 / c1) * v1.dot(F[i][1]) * v1;
    const Vec3 tL = t[i] - (2.0 / c1) * v1.dot(t[i]) * v1;
    const Vec3 v2 = t[i + 1] - tL;
    const double c2 = v2.dot(v2);
    Vec3 r = c2 > 1e-30 ? Vec3(rL - (2.0 / c2) * v2.dot(rL) * v2) : rL;
    r = (r - r.dot(t[i + 1]) * t[i + 1]).normalized();
    F[i + 1] = {t[i + 1], r, t[i + 1].cross(r)};
  }
  return F;
}

std::vector<Vec3> read_centerline(const std::string& path) {
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
    if (!(is >> y >> z))
      throw std::runtime_error(path + ":" + std::to_string(ln) + ": expected three numbers x y z");
    pts.emplace_back(x, y, z);
  }
  if (pts.size() < 2) throw std::runtime_error(path + ": centerline needs at least 2 points");
  return pts;
}

namespace {

// Maps straight-stent cylindrical coordinates (θ, z, r) onto a centerline.
struct Warp {
  std::vector<Vec3> pts;
  std::vector<double> s;
  std::vector<std::array<Vec3, 3>> F;
  std::vector<Eigen::Quaterniond> Q;
  double offset = 0;
  bool straight = true;

  void locate(double z, Vec3& c, Vec3& n1, Vec3& n2) const {
    if (straight) {
      c = Vec3(0, 0, z);
      n1 = Vec3::UnitX();
      n2 = Vec3::UnitY();
      return;
    }
    const double sa = z + offset;
    int i = 0;
    const int m = static_cast<int>(s.size());
    while (i + 2 < m && sa > s[i + 1]) ++i;
    const double len = s[i + 1] - s[i];
    const double t = (sa - s[i]) / len;  // may be outside [0,1] at the ends (extrapolation)
    c = pts[i] + t * (pts[i + 1] - pts[i]);
    const double tc = std::clamp(t, 0.0, 1.0);
    const Eigen::Quaterniond q = Q[i].slerp(tc, Q[i + 1]);
    const Mat3 R = q.toRotationMatrix();
    n1 = R.col(1);
    n2 = R.col(2);
  }
  Vec3 map(double theta, double z, double r) const {
    Vec3 c, n1, n2;
    locate(z, c, n1, n2);
    return c + r * (std::cos(theta) * n1 + std::sin(theta) * n2);
  }
  Vec3 radial(double theta, double z) const {
    Vec3 c, n1, n2;
    locate(z, c, n1, n2);
    return std::cos(theta) * n1 + std::sin(theta) * n2;
  }
};

}  // namespace

StentMesh generate_corrugated_rings(const StentParameters& p, const std::vector<Vec3>& centerline) {
  if (p.rings < 1 || p.crowns < 2 || p.connectors < 0 || p.elements_per_strut < 1 ||
      p.elements_per_connector < 1 || !(p.crimped_diameter > 0) || !(p.strut_height > 0) ||
      !(p.ring_pitch > 0))
    throw std::invalid_argument("invalid stent parameters");
  if (p.connectors > p.crowns) throw std::invalid_argument("more connectors than crowns");
  Warp W;
  const double length = (p.rings - 1) * p.ring_pitch + p.strut_height;
  if (!centerline.empty()) {
    W.straight = false;
    W.pts = centerline;
    W.s.assign(centerline.size(), 0.0);
    for (size_t i = 1; i < centerline.size(); ++i)
      W.s[i] = W.s[i - 1] + (centerline[i] - centerline[i - 1]).norm();
    W.F = rotation_minimizing_frames(centerline);
    for (const auto& f : W.F) {
      Mat3 R;
      R.col(0) = f[0];
      R.col(1) = f[1];
      R.col(2) = f[2];
      W.Q.emplace_back(R);
    }
    W.offset = p.start >= 0 ? p.start : 0.5 * (W.s.back() - length);
    if (W.offset < 0 || W.offset + length > W.s.back() + 1e-9)
      throw std::invalid_argument("stent (" + std::to_string(length) +
                                  " mm) does not fit on the centerline (" +
                                  std::to_string(W.s.back()) + " mm)");
  }
  StentMesh m;
  const double r = 0.5 * p.crimped_diameter;
  const int nc = 2 * p.crowns;
  const double dth = 2.0 * M_PI / nc;
  std::map<std::pair<int, int>, int> crown_node;  // (ring, j) → node
  auto add_node = [&](double th, double z) {
    m.nodes.push_back(W.map(th, z, r));
    return static_cast<int>(m.nodes.size()) - 1;
  };
  auto crown_z = [&](int k, int j) { return k * p.ring_pitch + ((j % 2) ? p.strut_height : 0.0); };
  for (int k = 0; k < p.rings; ++k)
    for (int j = 0; j < nc; ++j) crown_node[{k, j}] = add_node(j * dth, crown_z(k, j));
  // a polyline on the cylinder from (th0, z0) to (th1, z1) with n elements
  auto add_line = [&](int a, int b, double th0, double z0, double th1, double z1, int n, int kind,
                      int group) {
    int prev = a;
    for (int i = 1; i <= n; ++i) {
      const double f = static_cast<double>(i) / n;
      const int cur = i == n ? b : add_node(th0 + f * (th1 - th0), z0 + f * (z1 - z0));
      const double fm = (i - 0.5) / n;
      m.elements.push_back({prev, cur});
      m.element_up.push_back(W.radial(th0 + fm * (th1 - th0), z0 + fm * (z1 - z0)));
      m.element_kind.push_back(kind);
      m.element_group.push_back(group);
      prev = cur;
    }
  };
  for (int k = 0; k < p.rings; ++k)
    for (int j = 0; j < nc; ++j) {
      const int j1 = (j + 1) % nc;
      add_line(crown_node[{k, j}], crown_node[{k, j1}], j * dth, crown_z(k, j), (j + 1) * dth,
               crown_z(k, j1), p.elements_per_strut, 0, m.num_struts++);
    }
  for (int k = 0; k + 1 < p.rings; ++k)
    for (int i = 0; i < p.connectors; ++i) {
      // crown index m (0..crowns−1) of the top crown j = 2m+1; shifted by half the spacing on
      // odd gaps so that connectors alternate between gaps
      const double spacing = static_cast<double>(p.crowns) / p.connectors;
      const int mcrown = static_cast<int>(std::lround(i * spacing + ((k % 2) ? 0.5 * spacing : 0.0))) % p.crowns;
      const int j = 2 * mcrown + 1;
      const int j1 = (j + 1) % nc;
      add_line(crown_node[{k, j}], crown_node[{k + 1, j1}], j * dth, crown_z(k, j), (j + 1) * dth,
               crown_z(k + 1, j1),
               p.elements_per_connector, 1, m.num_connectors++);
    }
  // fixation: 4 bottom crowns of a ring, 90° apart (middle ring; every ring)
  auto ring_nodes = [&](int k, std::vector<int>& out) {
    for (int q = 0; q < 4; ++q) {
      int j = static_cast<int>(std::lround(q * nc / 4.0));
      if (j % 2) --j;
      const int node = crown_node[{k, (j + nc) % nc}];
      if (std::find(out.begin(), out.end(), node) == out.end()) out.push_back(node);
    }
  };
  ring_nodes(p.rings / 2, m.fixation_nodes);
  for (int k = 0; k < p.rings; ++k) ring_nodes(k, m.ring_fixation_nodes);
  for (int j = 0; j < nc; ++j) {
    if (j % 2 == 0) m.distal_nodes.push_back(crown_node[{0, j}]);
    else if (p.rings > 1) m.distal_nodes.push_back(crown_node[{p.rings - 1, j}]);
    m.central_nodes.push_back(crown_node[{(p.rings - 1) / 2, j}]);
    if (p.rings % 2 == 0) m.central_nodes.push_back(crown_node[{p.rings / 2, j}]);
  }
  if (W.straight)
    m.axis = {Vec3(0, 0, -1.0), Vec3(0, 0, length + 1.0)};
  else
    m.axis = centerline;
  return m;
}

}  // namespace angio::beam
