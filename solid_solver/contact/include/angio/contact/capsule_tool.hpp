// Rigid analytic tool for a "virtual insertion": the set of points within radius R of a polyline
// axis (a cylinder along the device's centerline with rounded ends, a capsule) pushes surface nodes
// out of itself by a penalty. Growing R opens a lesion narrower than the device before the device
// is placed; shrinking it lets the wall come to rest on the device. The approach follows the
// rigid-cylinder opening of stenosed arteries used before stent placement in the literature
// (Zahedmanesh, Kelly, Lally, J Biomech 43 (2010) 2126; Mortier et al., Ann Biomed Eng 38 (2010) 88).
//
// Per node a (current position x, reference lumped area A_a) with distance r from the axis:
//   Π_a = ½ ε A_a ⟨R − r⟩²   (ε in N/mm³: a pressure per mm of penetration, as the balloon–artery pair)
//   r_a = dΠ_a/dx = −ε A_a (R − r) e_r,            e_r = (x − foot)/r
//   K_a = ε A_a [ e_r e_rᵀ − (R − r)/r (P − e_r e_rᵀ) ]
// with P = I − t tᵀ where the foot lies inside a segment of tangent t, P = I where it is a vertex
// (the rounded ends and outer corners), both exact derivatives of r. Units: mm, N.
#pragma once

#include <vector>

#include "angio/contact/face.hpp"

namespace angio::contact {

struct AxisDistance {
  double r = 0.0;             // distance from the polyline (mm)
  Vec3 foot = Vec3::Zero();   // closest point on it
  Vec3 e_r = Vec3::Zero();    // (x − foot)/r; zero on the axis
  Mat3 P = Mat3::Identity();  // d(x − foot)/dx: I − t tᵀ inside a segment, I at a vertex
};

// Closest point of the polyline (>= 2 points, segments of positive length) to x.
AxisDistance polyline_distance(const std::vector<Vec3>& axis, const Vec3& x);

struct ToolNodeContact {
  bool active = false;       // r < R
  double penetration = 0.0;  // R − r (mm) when active
  double energy = 0.0;       // Π_a (N mm)
  Vec3 r = Vec3::Zero();     // dΠ_a/dx (N): minus the force on the node
  Mat3 K = Mat3::Zero();     // d²Π_a/dx² (N/mm)
};

// The penalty of the capsule of radius R on one node; eps_area = ε A_a (N/mm). A node on the axis
// itself (r = 0, no direction to push) is reported active without force.
ToolNodeContact capsule_node(const AxisDistance& d, double R, double eps_area);

}  // namespace angio::contact
