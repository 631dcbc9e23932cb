// Spatial search over the faces of one contact surface: bounding-volume (AABB) tree over face boxes
// inflated by a search radius. Holds no solver state besides the current face geometry: call update()
// with the current nodal coordinates before every contact evaluation (each Newton iteration).
#pragma once
#include <vector>

#include "angio/contact/face.hpp"
#include "angio/contact/normal_field.hpp"
#include "angio/contact/projection.hpp"

namespace angio::contact {

// Binary AABB tree (median split along the longest axis of the box centres, up to 4 items per leaf).
class AabbTree {
 public:
  void build(const std::vector<Aabb>& boxes);
  // Same items, new boxes: recompute node boxes bottom-up (topology kept).
  void refit(const std::vector<Aabb>& boxes);
  // Items whose box contains p / overlaps b (appended to out, unsorted).
  void query(const Vec3& p, std::vector<int>& out) const;
  // Items whose box, shrunk by `shrink` (>= 0) on every side, contains p.
  void query(const Vec3& p, double shrink, std::vector<int>& out) const;
  void query(const Aabb& b, std::vector<int>& out) const;
  std::size_t size() const { return items_.size(); }

 private:
  struct Node {
    Aabb box;
    int left = -1, right = -1;  // children (internal node)
    int begin = 0, end = 0;     // item range (leaf, left < 0)
  };
  int build_node(int begin, int end, const std::vector<Aabb>& boxes);
  std::vector<Node> nodes_;
  std::vector<int> items_;
  std::vector<Aabb> boxes_;
};

// Closest point of a point on a surface.
struct SurfaceProjection {
  bool found = false;  // some face within the search radius
  int face = -1;       // index into Surface::faces
  Projection proj;
};

// Projection of a point along the averaged normal field (normal_field.hpp).
struct SurfaceNormalProjection {
  bool found = false;  // a face with a valid projection and |d| <= radius
  int face = -1;
  NormalFieldProjection proj;
};

// Where a point projected at an earlier evaluation (its face and the face parameters there): a start for
// the next projection of the same point. face = -1: none.
struct ProjectionHint {
  int face = -1;
  Vec2 xi = Vec2::Zero();
};

class SurfaceSearch {
 public:
  // radius: faces farther than `radius` from a query point are ignored (mm).
  // The constructor finds the free (boundary) edges of the surface: edges, keyed by their two corner node ids,
  // that belong to one face only. A projection onto a free edge or a corner on a free edge from BEHIND the
  // surface (d < 0) is rejected: such a point has passed beside the surface's rim, not through it
  // (see solid_solver/contact/README.md, "Free edges"). Disable with reject_behind_free_edges = false.
  SurfaceSearch(const Surface& surface, double radius, bool reject_behind_free_edges = true);
  // Gather face coordinates from the current configuration, recompute boxes, rebuild (default) or refit the tree;
  // with the normal field, the nodal normals and (normal_derivatives) their derivatives, which a tangent needs.
  void update(std::span<const Vec3> coords, bool rebuild = true, bool normal_derivatives = true);
  // Faces whose box inflated by the radius contains p, sorted ascending.
  void candidates(const Vec3& p, std::vector<int>& faces) const;
  // Faces whose inflated box overlaps b, sorted ascending.
  void candidates(const Aabb& b, std::vector<int>& faces) const;
  // Closest point over the candidate faces (ties: lowest face index); found only if distance <= radius.
  SurfaceProjection closest(const Vec3& p, const ProjectionOptions& opt = {}) const;
  // Projection along the averaged nodal normal field (enable_normal_field()) over the candidate faces: the valid one
  // with the smallest |d| (ties: lowest face index); found only if |d| <= radius.
  // A hint's face, if it is a candidate, is projected first and from the hint's parameters: the same result
  // (to the projection's Newton tolerance) with fewer projections and iterations when the point and the
  // surface moved little since.
  SurfaceNormalProjection along_normals(const Vec3& p, double inside_tol = 1e-10,
                                        const ProjectionHint* hint = nullptr) const;
  // Same over all faces (reference for tests; ignores the tree but applies the radius).
  SurfaceProjection closest_brute_force(const Vec3& p, const ProjectionOptions& opt = {}) const;

  const Surface& surface() const { return *surface_; }
  double radius() const { return radius_; }
  const FaceX& face_coords(int f) const { return X_[f]; }
  // Averaged nodal normal field (normal_field.hpp), computed by update() once enabled.
  void enable_normal_field(bool on = true) { normal_field_ = on; }
  const FaceX& face_normals(int f) const { return normals_.face[f]; }
  const NodeNormal& node_normal(int id) const { return normals_.node[id]; }
  bool normal_derivatives() const { return normals_.derivatives; }
  const Aabb& face_box(int f) const { return boxes_[f]; }  // inflated
  bool ready() const { return ready_; }
  // Bit e (0..3): edge e of face f is free; bit 4 + c: corner c lies on a free edge.
  unsigned free_mask(int f) const { return free_[f]; }

 private:
  const Surface* surface_;
  double radius_;
  bool ready_ = false;
  bool reject_free_ = true;
  std::vector<unsigned> free_;
  std::vector<FaceX> X_;
  bool normal_field_ = false;
  NodalNormals normals_;
  std::vector<Aabb> boxes_;
  AabbTree tree_;
};

}  // namespace angio::contact
