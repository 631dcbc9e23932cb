#include "angio/contact/search.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

namespace angio::contact {

void AabbTree::build(const std::vector<Aabb>& boxes) {
  nodes_.clear();
  boxes_ = boxes;
  items_.resize(boxes.size());
  std::iota(items_.begin(), items_.end(), 0);
  if (boxes.empty()) return;
  nodes_.reserve(2 * boxes.size());
  build_node(0, static_cast<int>(boxes.size()), boxes);
}

int AabbTree::build_node(int begin, int end, const std::vector<Aabb>& boxes) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Aabb box, cbox;
  for (int i = begin; i < end; ++i) {
    box.extend(boxes[items_[i]]);
    cbox.extend(boxes[items_[i]].center());
  }
  nodes_[id].box = box;
  if (end - begin <= 4) {
    nodes_[id].begin = begin;
    nodes_[id].end = end;
    return id;
  }
  int axis = 0;
  (cbox.hi - cbox.lo).maxCoeff(&axis);
  const int mid = (begin + end) / 2;
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                   [&](int a, int b) { return boxes[a].center()[axis] < boxes[b].center()[axis]; });
  const int l = build_node(begin, mid, boxes);
  const int r = build_node(mid, end, boxes);
  nodes_[id].left = l;
  nodes_[id].right = r;
  return id;
}

void AabbTree::refit(const std::vector<Aabb>& boxes) {
  if (boxes.size() != items_.size()) throw std::invalid_argument("AabbTree::refit: item count changed");
  boxes_ = boxes;
  // Children have larger indices than their parent (pre-order construction): sweep backwards.
  for (int i = static_cast<int>(nodes_.size()) - 1; i >= 0; --i) {
    Node& nd = nodes_[i];
    Aabb b;
    if (nd.left < 0) {
      for (int k = nd.begin; k < nd.end; ++k) b.extend(boxes[items_[k]]);
    } else {
      b.extend(nodes_[nd.left].box);
      b.extend(nodes_[nd.right].box);
    }
    nd.box = b;
  }
}

void AabbTree::query(const Vec3& p, std::vector<int>& out) const { query(p, 0.0, out); }

// A box query with the inverted box [p + shrink, p - shrink]: it overlaps a box B iff B.lo + shrink <= p <=
// B.hi - shrink, i.e. iff B shrunk by `shrink` contains p (shrink 0: a degenerate box, overlaps == contains).
// A node's box shrunk contains every child's box shrunk, so the descent stays exact.
void AabbTree::query(const Vec3& p, double shrink, std::vector<int>& out) const {
  Aabb b;
  b.lo = p.array() + shrink;
  b.hi = p.array() - shrink;
  query(b, out);
}

void AabbTree::query(const Aabb& b, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& nd = nodes_[stack[--top]];
    if (!nd.box.overlaps(b)) continue;
    if (nd.left < 0) {
      for (int k = nd.begin; k < nd.end; ++k)
        if (boxes_[items_[k]].overlaps(b)) out.push_back(items_[k]);
    } else {
      stack[top++] = nd.left;
      stack[top++] = nd.right;
    }
  }
}

SurfaceSearch::SurfaceSearch(const Surface& surface, double radius, bool reject_behind_free_edges)
    : surface_(&surface), radius_(radius), reject_free_(reject_behind_free_edges) {
  if (!(radius >= 0)) throw std::invalid_argument("SurfaceSearch: radius must be >= 0");
  std::map<std::pair<int, int>, int> count;
  auto key = [](int a, int b) { return a < b ? std::pair{a, b} : std::pair{b, a}; };
  for (const Face& f : surface.faces) {
    const int nc = num_corners(f.kind);
    for (int e = 0; e < nc; ++e) ++count[key(f.nodes[e], f.nodes[(e + 1) % nc])];
  }
  free_.assign(surface.faces.size(), 0u);
  for (std::size_t i = 0; i < surface.faces.size(); ++i) {
    const Face& f = surface.faces[i];
    const int nc = num_corners(f.kind);
    for (int e = 0; e < nc; ++e)
      if (count[key(f.nodes[e], f.nodes[(e + 1) % nc])] == 1) {
        free_[i] |= 1u << e;
        free_[i] |= 1u << (4 + e);
        free_[i] |= 1u << (4 + (e + 1) % nc);
      }
  }
}

void SurfaceSearch::update(std::span<const Vec3> coords, bool rebuild, bool normal_derivatives) {
  const auto& faces = surface_->faces;
  const bool same = ready_ && X_.size() == faces.size();
  X_.resize(faces.size());
  boxes_.resize(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    X_[f] = gather(faces[f], coords);
    boxes_[f] = angio::contact::face_box(faces[f].kind, X_[f]);
    boxes_[f].inflate(radius_);
  }
  if (normal_field_) nodal_normals(*surface_, X_, coords.size(), normals_, normal_derivatives);
  if (rebuild || !same)
    tree_.build(boxes_);
  else
    tree_.refit(boxes_);
  ready_ = true;
}

void SurfaceSearch::candidates(const Vec3& p, std::vector<int>& faces) const {
  if (!ready_) throw std::logic_error("SurfaceSearch: update() not called");
  faces.clear();
  tree_.query(p, faces);
  std::sort(faces.begin(), faces.end());
}

void SurfaceSearch::candidates(const Aabb& b, std::vector<int>& faces) const {
  if (!ready_) throw std::logic_error("SurfaceSearch: update() not called");
  faces.clear();
  tree_.query(b, faces);
  std::sort(faces.begin(), faces.end());
}

namespace {
// Squared distance from p to a box (0 inside).
double box_dist2(const Aabb& b, const Vec3& p) {
  const Vec3 d = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0);
  return d.squaredNorm();
}

// A face already projected before the visit (SurfaceSearch::along_normals' hint).
template <class Proj>
struct Visited {
  int face = -1;
  double d = std::numeric_limits<double>::infinity();
  Proj proj{};
};

// Best projection over `faces`: project(f, proj) projects onto face f and returns the distance |p - s| (infinity to
// reject the face). Faces are visited by increasing distance from p to their (uninflated) boxes, and the visit stops
// once that lower bound exceeds the best distance so far (exact pruning: s lies in its face's box). `seed` (a face
// projected already, or none) is the best so far from the start and is not visited again. Ties: lowest face
// index, whatever the order of the visit. Result (SurfaceProjection or SurfaceNormalProjection): found if the best
// distance is within radius.
template <class Result, class Project>
Result nearest_first(const std::vector<Aabb>& boxes, double inflation, const std::vector<int>& faces, const Vec3& p,
                     double radius, Project project, const Visited<decltype(Result::proj)>& seed = {}) {
  using Proj = decltype(Result::proj);
  int best = seed.d < std::numeric_limits<double>::infinity() ? seed.face : -1;
  Proj best_proj = seed.proj, pr{};
  double dmin = seed.d;
  auto beyond = [&](double lb2) { return std::sqrt(lb2) > dmin * (1.0 + 1e-12) + 1e-300; };
  thread_local std::vector<std::pair<double, int>> order;
  order.clear();
  for (int f : faces) {
    if (f == seed.face) continue;
    Aabb b = boxes[f];
    b.inflate(-inflation);
    const double lb2 = box_dist2(b, p);
    if (!beyond(lb2)) order.emplace_back(lb2, f);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [lb2, f] : order) {
    if (beyond(lb2)) break;
    const double d = project(f, pr);
    if (d < dmin || (d == dmin && d < std::numeric_limits<double>::infinity() && f < best)) {
      dmin = d;
      best = f;
      best_proj = pr;
    }
  }
  Result r;
  r.found = best >= 0 && dmin <= radius;
  if (r.found) {
    r.face = best;
    r.proj = best_proj;
  }
  return r;
}

// Closest point over `faces`.
SurfaceProjection closest_over(const Surface& s, const std::vector<FaceX>& X, const std::vector<Aabb>& boxes,
                               double inflation, std::vector<int>& faces, const Vec3& p, double radius,
                               const ProjectionOptions& opt, const std::vector<unsigned>* free) {
  constexpr double reject = std::numeric_limits<double>::infinity();
  return nearest_first<SurfaceProjection>(boxes, inflation, faces, p, radius, [&](int f, Projection& pr) {
    pr = project(s.faces[f].kind, X[f], s.normal_sign, p, opt);
    if (!pr.valid) return reject;
    if (free && pr.location != Location::Interior && pr.d < 0.0) {
      const unsigned bit = pr.location == Location::Edge ? 1u << pr.index : 1u << (4 + pr.index);
      if ((*free)[f] & bit) return reject;
    }
    return pr.distance;
  });
}
}  // namespace

SurfaceProjection SurfaceSearch::closest(const Vec3& p, const ProjectionOptions& opt) const {
  thread_local std::vector<int> cand;
  candidates(p, cand);
  return closest_over(*surface_, X_, boxes_, radius_, cand, p, radius_, opt, reject_free_ ? &free_ : nullptr);
}

SurfaceNormalProjection SurfaceSearch::along_normals(const Vec3& p, double inside_tol,
                                                     const ProjectionHint* hint) const {
  if (!normal_field_) throw std::logic_error("SurfaceSearch: along_normals() needs enable_normal_field()");
  if (!ready_) throw std::logic_error("SurfaceSearch: update() not called");
  auto project = [&](int f, const Vec2* start) {
    return project_along_normals(surface_->faces[f].kind, X_[f], normals_.face[f], p, inside_tol, start);
  };
  // |d| = |p - s|: the pruning of the closest point applies unchanged
  auto distance = [](const NormalFieldProjection& pr) {
    return pr.valid ? std::abs(pr.d) : std::numeric_limits<double>::infinity();
  };
  // The hint's face first, if it is a candidate (its inflated box holds p): its distance d bounds the
  // rest, so only faces whose box lies within d of p are gathered (a tree query with the boxes shrunk by
  // radius - d; a little wider, for the rounding of the boxes), not every face within the radius.
  Visited<NormalFieldProjection> seed;
  double shrink = 0.0;
  if (hint && hint->face >= 0 && hint->face < int(boxes_.size()) && boxes_[hint->face].contains(p)) {
    seed.face = hint->face;
    seed.proj = project(hint->face, &hint->xi);
    seed.d = distance(seed.proj);
    if (seed.d <= radius_)
      shrink = std::max(0.0, radius_ - seed.d * (1.0 + 1e-9) - 1e-9 * radius_);
    else if (!seed.proj.valid)
      seed = {};  // no root in the face from there: the face is projected again from its centre below
  }
  thread_local std::vector<int> cand;
  cand.clear();
  tree_.query(p, shrink, cand);  // unsorted: nearest_first orders them itself and breaks ties by face index
  return nearest_first<SurfaceNormalProjection>(
      boxes_, radius_, cand, p, radius_,
      [&](int f, NormalFieldProjection& pr) {
        pr = project(f, nullptr);
        return distance(pr);
      },
      seed);
}

SurfaceProjection SurfaceSearch::closest_brute_force(const Vec3& p, const ProjectionOptions& opt) const {
  if (!ready_) throw std::logic_error("SurfaceSearch: update() not called");
  std::vector<int> all(surface_->faces.size());
  std::iota(all.begin(), all.end(), 0);
  return closest_over(*surface_, X_, boxes_, radius_, all, p, radius_, opt, reject_free_ ? &free_ : nullptr);
}

}  // namespace angio::contact
