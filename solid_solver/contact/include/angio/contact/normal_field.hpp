// Averaged nodal normal field of a faceted surface and the projection of a point along it.
//
// The closest-point projection (projection.hpp) gives a contact normal that jumps where the closest
// face changes across a concave kink (a groove, e.g. the balloon wrapped around a strut): the line
// load on a point above the groove switches between the two face normals, the solid's residual is
// discontinuous there and Newton (and the coupling iteration) stall at the size of the jump.
// The averaged normal field, as used by mortar methods (Yang, Laursen & Meng 2005, IJNME 62:1183;
// Popp et al. 2010, IJNME 83:1428), is continuous over the whole surface:
//   n_a  = normal_sign * normalize( sum over faces f at node a of the unit face normal of f at a ),
//   m(xi) = sum_a N_a(xi) n_a,   nu = m / |m|,
// and a point x is projected along it: x = x_s(xi) + alpha m(xi) (3 equations for xi, alpha).
// The signed distance d = alpha |m| and nu are then continuous in x and in the nodes, so the penalty
// line load q = f(d - R) nu is continuous too.
// Units: mm.
#pragma once
#include <span>
#include <vector>

#include "angio/contact/face.hpp"

namespace angio::contact {

// Unit normal at one surface node and its derivative with respect to the coordinates of the nodes of the
// faces around it (the node's "ring", itself included).
struct NodeNormal {
  Vec3 n = Vec3::Zero();
  std::vector<int> ring;  // node ids
  Eigen::MatrixXd dn;     // dn/dX_ring (3 x 3 ring.size())
};

// Averaged nodal normals of a surface: `node[id]` for every node id used by a face (ids index an array of
// num_nodes entries), and per face the gathered normals (column a = normal at node a of the face).
struct NodalNormals {
  std::vector<NodeNormal> node;
  std::vector<FaceX> face;
  bool derivatives = false;  // NodeNormal::dn holds the current configuration's
};
// The ring of every node id used by a face of `s` (ids index an array of num_nodes entries): the nodes
// of the faces around it, itself included, in the order met; empty for the others. The nodes a nodal
// normal depends on (NodeNormal::ring), and so the reach of a point's tangent past its face.
std::vector<std::vector<int>> node_rings(const Surface& s, std::size_t num_nodes);

// `out` keeps its rings and storage between calls on the same surface (one call per Newton iteration):
// the first call builds them, later calls only recompute the values. derivatives = false: the normals
// only (NodeNormal::dn left stale, `out.derivatives` false); a residual needs no more, and the
// derivatives are most of the cost.
void nodal_normals(const Surface& s, std::span<const FaceX> X, std::size_t num_nodes, NodalNormals& out,
                   bool derivatives = true);

struct NormalFieldProjection {
  bool valid = false;  // Newton converged and xi lies in the face (tolerance `inside_tol`)
  Vec2 xi = Vec2::Zero();
  Vec3 s = Vec3::Zero();   // x_s(xi)
  Vec3 nu = Vec3::Zero();  // unit normal of the field at xi
  double alpha = 0.0;      // x = s + alpha m(xi)
  double d = 0.0;          // signed distance along nu: alpha |m|
  int iterations = 0;
};

// Solves x_s(xi) + alpha m(xi) = x on one face by Newton from the face centre, or from `start` (e.g.
// where the same point projected at an earlier evaluation: fewer iterations, the same root).
NormalFieldProjection project_along_normals(FaceKind k, const FaceX& X, const FaceX& Nn, const Vec3& x,
                                            double inside_tol = 1e-10, const Vec2* start = nullptr, int max_iter = 30);

// First derivatives of the projection with respect to u = [x (3), X_0 (3), ..., X_{nn-1} (3),
// n_0 (3), ..., n_{nn-1} (3)]: the point, the face's nodes and its nodal normals taken as independent
// (NodeNormal::dn chains the normals to the nodes around the face).
struct NormalFieldLinearization {
  int m = 0;              // 3 + 6 nn
  ShapeN N;               // shape functions at xi
  ShapeD dN;              // their derivatives
  Eigen::MatrixXd dxi;    // dxi/du (2 x m)
  Eigen::RowVectorXd dd;  // dd/du (1 x m)
  Eigen::MatrixXd dnu;    // dnu/du (3 x m)
};
void linearize(FaceKind k, const FaceX& X, const FaceX& Nn, const NormalFieldProjection& p,
               NormalFieldLinearization& out);

}  // namespace angio::contact
