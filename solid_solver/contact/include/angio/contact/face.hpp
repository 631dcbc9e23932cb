// Contact surface faces: quad4 (faces of hex8), tri3, tri6 (faces of tet10).
// Node ordering follows gmsh (same as angio::solid):
//   quad4: corners at (xi,eta) = (-1,-1), (1,-1), (1,1), (-1,1)
//   tri3 : corners at (0,0), (1,0), (0,1)
//   tri6 : corners as tri3, then mid-edge nodes of edges 01, 12, 20
// Orientation: nodes counter-clockwise seen from the side the face normal points to, i.e.
//   n_face = (x_,xi x x_,eta) / |x_,xi x x_,eta|  (outward for faces oriented out of their volume).
// A Surface carries normal_sign (+1 or -1): the contact normal is normal_sign * n_face and must point
// toward the other body (the beam, or the slave surface).
// Units: mm.
#pragma once
#include <Eigen/Dense>
#include <array>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace angio::contact {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

enum class FaceKind { Quad4, Tri3, Tri6 };
inline constexpr int kMaxFaceNodes = 6;

// Nodal coordinates of one face: column a = node a.
using FaceX = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxFaceNodes>;
using ShapeN = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxFaceNodes, 1>;
// dN/dxi (col 0), dN/deta (col 1)
using ShapeD = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::ColMajor, kMaxFaceNodes, 2>;
// second derivatives: col 0 = d2N/dxi2, col 1 = d2N/deta2, col 2 = d2N/dxi deta
using ShapeDD = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::ColMajor, kMaxFaceNodes, 3>;

int num_nodes(FaceKind k);
int num_corners(FaceKind k);  // = number of edges
const char* name(FaceKind k);

// Shape functions N, first and (optionally) second derivatives at xi.
void shape(FaceKind k, const Vec2& xi, ShapeN& N, ShapeD* dN = nullptr, ShapeDD* ddN = nullptr);
// Parameter coordinates of a corner (0..num_corners-1).
Vec2 corner_xi(FaceKind k, int corner);
// Parameter coordinates of the face centre.
Vec2 center_xi(FaceKind k);
// Whether xi lies in the parameter domain (quad [-1,1]^2, triangle xi,eta >= 0, xi+eta <= 1), with tolerance.
bool inside(FaceKind k, const Vec2& xi, double tol = 0.0);
// Edge e runs from corner e to corner (e+1) % num_corners.

// One face of a contact surface: node ids index the caller's coordinate array.
struct Face {
  FaceKind kind = FaceKind::Quad4;
  std::array<int, kMaxFaceNodes> nodes{};
  int nn() const { return num_nodes(kind); }
};

struct Surface {
  std::string name;
  std::vector<Face> faces;
  double normal_sign = 1.0;  // contact normal = normal_sign * n_face (toward the other body)
};

// Gather the face's nodal coordinates from the global coordinate array.
FaceX gather(const Face& f, std::span<const Vec3> coords);

// Geometry of a face at xi.
struct FacePoint {
  Vec3 x;              // position
  Vec3 a1, a2;         // tangents x_,xi and x_,eta
  Vec3 a11, a22, a12;  // second derivatives
  Vec3 n;              // unit normal, normal_sign * (a1 x a2)/|a1 x a2|
  double j = 0.0;      // |a1 x a2| (area element per unit parameter area)
};
FacePoint evaluate(FaceKind k, const FaceX& X, const Vec2& xi, double normal_sign = 1.0);

// [v]x: the matrix of v x (.)
Mat3 skew(const Vec3& v);
// Derivative of the area vector x_,xi x x_,eta with respect to the face node b, whose shape function has the
// derivatives dN_xi, dN_eta at the point (tangents a1 = x_,xi, a2 = x_,eta there):
//   d(a1 x a2)/dX_b = dN_eta [a1]x - dN_xi [a2]x
inline Mat3 d_area_vector(double dN_xi, double dN_eta, const Vec3& a1, const Vec3& a2) {
  return dN_eta * skew(a1) - dN_xi * skew(a2);
}

// Quadrature on the parameter domain (weights sum to 4 on quad, 1/2 on triangle).
// degree: polynomial degree integrated exactly. quad: n x n Gauss points, n = clamp((degree+2)/2, 1, 4);
// triangle: degree <= 1 -> 1 point, 2 -> 3 points, >= 3 -> 6 points (exact to degree 4).
struct QuadratureRule {
  std::vector<Vec2> xi;
  std::vector<double> w;
};
QuadratureRule face_rule(FaceKind k, int degree);

// Axis-aligned bounding box.
struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void extend(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  void inflate(double r) {
    lo.array() -= r;
    hi.array() += r;
  }
  bool contains(const Vec3& p) const { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); }
  bool overlaps(const Aabb& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
  Vec3 center() const { return 0.5 * (lo + hi); }
};
// A box that contains the whole (curved) face: node hull for quad4/tri3 (bilinear/linear maps stay in the
// convex hull of their nodes); for tri6 the hull of the Bezier control points (corners and 2 x_mid - (x_p+x_q)/2).
Aabb face_box(FaceKind k, const FaceX& X);

}  // namespace angio::contact
