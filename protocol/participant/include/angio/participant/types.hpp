// Interface data exchanged between the beam and the solid side (docs/design.md §5.1).
// Plain C++ types so that neither solver depends on the other's linear algebra.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace angio::participant {

using Vec3 = std::array<double, 3>;

// Contact sample points along the stent centerline: the Gauss points of the beam's contact
// integration. x: current position (mm), w: arc-length weight (mm), radius: contact radius (mm).
struct SamplePoints {
  std::vector<Vec3> x;
  std::vector<double> w;
  std::vector<double> radius;
  std::size_t size() const { return x.size(); }
};

struct SolveStats {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;
  std::vector<double> residual_history;
  std::string message;  // why it failed, for the error report
};

// Robin mode (docs/design.md §5.3): frozen contact planes per sample point, point s (mm), unit normal n
// toward the beam and penalty eps (N/mm²; 0: no plane at this point). The beam adds the penalty
// law q(x) = −eps·⟨(x − s)·n − R⟩·n of each plane to its loads and linearizes it in its Newton.
// K planes per sample point (K ≥ 1), point-major: plane j of point i at index i·K + j; a point
// pressed between two surfaces (stent between balloon and artery) has one plane per surface.
struct ContactPlanes {
  std::vector<Vec3> s, n;
  std::vector<double> eps;
  double g0 = 0.0;  // mm, regularization of the penalty law (plane_penalty.hpp), 0 = linear
  std::size_t size() const { return eps.size(); }
};
// K for `planes` planes over `points` sample points; 0 if they do not divide (a malformed message).
inline std::size_t planes_per_point(std::size_t planes, std::size_t points) {
  return points > 0 && planes >= points && planes % points == 0 ? planes / points : 0;
}

// Solid → beam: the contact line loads q (N/mm) acting on the beam at each sample point, and for
// the robin mode per point and contact surface (K planes per point, as ContactPlanes) the closest
// surface point s, its unit normal n (toward the beam) and penalty eps (0: no face in range).
struct ContactReply {
  std::vector<Vec3> line_loads;
  std::vector<Vec3> surface_points;
  std::vector<Vec3> normals;
  std::vector<double> penalty;
  std::vector<std::uint8_t> active;
  double regularization = 0.0;  // g0 (mm) of the solid's line penalty law, 0 = linear (Eq. 4)
  int n_active = 0;
  double min_gap = 0.0;             // most negative gap (largest penetration), mm
  Vec3 total_force{0.0, 0.0, 0.0};  // sum of w·q over the points (N)
};

}  // namespace angio::participant
