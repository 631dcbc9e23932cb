#include "angio/geometry/centerline_scene.hpp"

#include <stdexcept>

namespace angio::geometry {

namespace {
std::vector<Vec3> points_from(const scene::Node& n) {
  if (!n.is_sequence() || n.size() < 2) n.fail("a list of at least two points [x, y, z] (mm)");
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const auto p = n.at(i).as_vec3();
    pts.emplace_back(p[0], p[1], p[2]);
  }
  return pts;
}
}  // namespace

Centerline centerline_from_scene(const scene::Node& node) {
  if (node.is_map()) {
    node.check_keys({"file", "points"});
    if (node.has("file") == node.has("points")) node.fail("exactly one of 'file' or 'points'");
    if (node.has("file")) {
      const std::string path = scene::resolve_path(node, node.string("file"));
      try {
        return read_centerline(path);
      } catch (const std::exception& e) {
        node.child("file").fail(std::string("a readable centerline file with distinct points 'x y z' per line (") +
                                e.what() + ")");
      }
    }
  } else if (!node.is_sequence()) {
    node.fail("{file: path} or {points: [[x, y, z], ...]}");
  }
  const scene::Node p = node.is_sequence() ? node : node.child("points");
  try {
    return Centerline(points_from(p));
  } catch (const std::invalid_argument& e) {
    p.fail(std::string("distinct consecutive points (") + e.what() + ")");
  }
  throw std::logic_error("unreachable");
}

}  // namespace angio::geometry
