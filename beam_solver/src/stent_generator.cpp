#include "angio/beam/stent_generator.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace angio::beam {

namespace {

// Where the straight stent's cylindrical coordinates (θ, z, r) go: the straight stent along +z
// from z = 0, or the warp onto a centerline with z = arc length − offset (paper §2.4; see
// angio::geometry::Centerline::map).
struct Placement {
  const geometry::Centerline* centerline = nullptr;
  double offset = 0;  // mm, arc length where the stent starts

  Vec3 map(double theta, double z, double r) const {
    if (centerline) return centerline->map(theta, z + offset, r);
    return Vec3(0, 0, z) + r * (std::cos(theta) * Vec3::UnitX() + std::sin(theta) * Vec3::UnitY());
  }
  Vec3 radial(double theta, double z) const {
    if (centerline) return centerline->radial(theta, z + offset);
    return std::cos(theta) * Vec3::UnitX() + std::sin(theta) * Vec3::UnitY();
  }
};

StentMesh generate(const StentParameters& p, const geometry::Centerline* centerline) {
  if (p.rings < 1 || p.crowns < 2 || p.connectors < 0 || p.elements_per_strut < 1 || p.elements_per_connector < 1 ||
      !(p.crimped_diameter > 0) || !(p.strut_height > 0) || !(p.ring_pitch > 0))
    throw std::invalid_argument("invalid stent parameters");
  if (p.connectors > p.crowns) throw std::invalid_argument("more connectors than crowns");
  Placement W;
  const double length = (p.rings - 1) * p.ring_pitch + p.strut_height;
  if (centerline) {
    W.centerline = centerline;
    const double L = centerline->length();
    W.offset = p.start >= 0 ? p.start : 0.5 * (L - length);
    if (W.offset < 0 || W.offset + length > L + 1e-9)
      throw std::invalid_argument("stent (" + std::to_string(length) + " mm) does not fit on the centerline (" +
                                  std::to_string(L) + " mm" +
                                  (p.start >= 0 ? ", starting at " + std::to_string(p.start) + " mm" : "") + ")");
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
  m.ring_crowns.resize(p.rings);
  for (int k = 0; k < p.rings; ++k)
    for (int j = 0; j < nc; ++j) {
      crown_node[{k, j}] = add_node(j * dth, crown_z(k, j));
      m.ring_crowns[k].push_back(crown_node[{k, j}]);
    }
  // a polyline on the cylinder from (th0, z0) to (th1, z1) with n elements
  auto add_line = [&](int a, int b, double th0, double z0, double th1, double z1, int n, int kind, int group) {
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
      add_line(crown_node[{k, j}], crown_node[{k, j1}], j * dth, crown_z(k, j), (j + 1) * dth, crown_z(k, j1),
               p.elements_per_strut, 0, m.num_struts++);
    }
  for (int k = 0; k + 1 < p.rings; ++k)
    for (int i = 0; i < p.connectors; ++i) {
      // crown index m (0..crowns−1) of the top crown j = 2m+1; shifted by half the spacing on
      // odd gaps so that connectors alternate between gaps
      const double spacing = static_cast<double>(p.crowns) / p.connectors;
      const int mcrown = static_cast<int>(std::lround(i * spacing + ((k % 2) ? 0.5 * spacing : 0.0))) % p.crowns;
      const int j = 2 * mcrown + 1;
      const int j1 = (j + 1) % nc;
      add_line(crown_node[{k, j}], crown_node[{k + 1, j1}], j * dth, crown_z(k, j), (j + 1) * dth, crown_z(k + 1, j1),
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
    if (j % 2 == 0)
      m.distal_nodes.push_back(crown_node[{0, j}]);
    else if (p.rings > 1)
      m.distal_nodes.push_back(crown_node[{p.rings - 1, j}]);
    m.central_nodes.push_back(crown_node[{(p.rings - 1) / 2, j}]);
    if (p.rings % 2 == 0) m.central_nodes.push_back(crown_node[{p.rings / 2, j}]);
  }
  if (!centerline)
    m.axis = {Vec3(0, 0, -1.0), Vec3(0, 0, length + 1.0)};
  else
    m.axis = centerline->points();
  return m;
}

}  // namespace

StentMesh generate_corrugated_rings(const StentParameters& p, const std::vector<Vec3>& centerline) {
  if (centerline.empty()) return generate(p, nullptr);
  const geometry::Centerline cl(centerline);  // std::invalid_argument if degenerate
  return generate(p, &cl);
}

StentMesh generate_corrugated_rings(const StentParameters& p, const geometry::Centerline& centerline) {
  return generate(p, &centerline);
}

}  // namespace angio::beam
