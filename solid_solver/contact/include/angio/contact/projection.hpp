// Closest-point projection of a point onto a face and the consistent linearization of the
// signed distance d = (x - s) . n with respect to the point and the face's nodal coordinates.
#pragma once
#include "angio/contact/face.hpp"

namespace angio::contact {

enum class Location { Interior, Edge, Corner };
const char* name(Location l);

struct ProjectionOptions {
  double tol = 1e-13;  // Newton step tolerance in parameter space
  int max_iter = 40;
  double inside_tol = 1e-10;  // parameter-space tolerance for accepting an interior solution
  // Newton starts from the closest of a few sample points (9 on quads, 7 on triangles). If it does not converge to
  // a minimum, or x is close to a centre of curvature of the face (smallest eigenvalue of G^-1 H = 1 - d kappa_max
  // below trust_eigenvalue, where a curved face can have several local minima), Newton is rerun from all sample
  // points, the best minimum is kept and compared with the edge minima.
  bool multi_start = true;
  double trust_eigenvalue = 0.5;
  bool check_edges = true;  // also minimize over the edges after an interior solution (global minimum on
                            // strongly curved faces); false: edges only if no interior minimum was found
};

// Result of projecting x onto one face (minimizing |x - x_s(xi)| over the parameter domain).
//  Interior: the unconstrained minimum lies in the domain; n = face normal at s (times normal_sign).
//  Edge:     minimum on edge `index` (corner index -> corner index+1); t in (0,1) along it.
//  Corner:   minimum at corner `index`.
//  For Edge and Corner, n = sign((x-s).n_face) * (x-s)/|x-s| (the point-to-edge / point-to-node normal,
//  which makes the distance and normal continuous across convex kinks of a faceted surface);
//  if |x-s| is ~0 the face normal is used.
struct Projection {
  bool valid = false;
  Location location = Location::Interior;
  int index = -1;              // edge or corner index (Edge/Corner)
  double t = 0.0;              // edge parameter (Edge)
  Vec2 xi = Vec2::Zero();      // parameter coordinates of s
  Vec3 s = Vec3::Zero();       // closest point
  Vec3 n = Vec3::Zero();       // unit contact normal (toward the side of x for edge/corner; face normal inside)
  Vec3 n_face = Vec3::Zero();  // normal_sign * face normal at s
  double distance = 0.0;       // |x - s|
  double d = 0.0;              // signed distance (x - s) . n
  int iterations = 0;
};

Projection project(FaceKind k, const FaceX& X, double normal_sign, const Vec3& x, const ProjectionOptions& opt = {});

// Derivatives of d = (x - s) . n (s, n from `p`) with respect to u = [x (3), X_0 (3), ..., X_{nn-1} (3)],
// where x and the face nodes are independent variables; the closest point
// (xi) and the normal follow from the projection conditions.
struct GapLinearization {
  int m = 0;              // 3 + 3 nn
  ShapeN N;               // shape functions at s
  Eigen::RowVectorXd dd;  // dd/du (1 x m)
  Eigen::MatrixXd dn;     // dn/du (3 x m)
  Eigen::MatrixXd dxi;    // dxi/du (2 x m)
  Eigen::MatrixXd hd;     // d2d/du2 (m x m), only if requested
};
void linearize(FaceKind k, const FaceX& X, double normal_sign, const Vec3& x, const Projection& p, bool hessian,
               GapLinearization& out);

}  // namespace angio::contact
