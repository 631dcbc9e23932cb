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

// A point query is a box query with a degenerate box (overlaps == contains for lo == hi == p).
void AabbTree::query(const Vec3& p, std::vector<int>& out) const {
  Aabb b;
  b.lo = p;
  b.hi = p;
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

// Best projection over `faces`: project(f, proj) projects onto face f and returns the distance |p - s| (infinity to
// reject the face). Faces are visited by increasing distance from p to their (uninflated) boxes, and the visit stops
// once that lower bound exceeds the best distance so far (exact pruning: s lies in its face's box). Ties: lowest
// face index. Result (SurfaceProjection or SurfaceNormalProjection): found if the best distance is within radius.
template <class Result, class Project>
Result nearest_first(const std::vector<Aabb>& boxes, double inflation, const std::vector<int>& faces, const Vec3& p,
                     double radius, Project project) {
  using Proj = decltype(Result::proj);
  thread_local std::vector<std::pair<double, int>> order;
  order.clear();
  for (int f : faces) {
    Aabb b = boxes[f];
    b.inflate(-inflation);
    order.emplace_back(box_dist2(b, p), f);
  }
  std::sort(order.begin(), order.end());
  int best = -1;
  Proj best_proj{}, pr{};
  double dmin = std::numeric_limits<double>::infinity();
  for (const auto& [lb2, f] : order) {
    if (std::sqrt(lb2) > dmin * (1.0 + 1e-12) + 1e-300) break;
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

SurfaceNormalProjection SurfaceSearch::along_normals(const Vec3& p, double inside_tol) const {
  if (!normal_field_) throw std::logic_error("SurfaceSearch: along_normals() needs enable_normal_field()");
  thread_local std::vector<int> cand;
  candidates(p, cand);
  // |d| = |p - s|: the pruning of the closest point applies unchanged
  return nearest_first<SurfaceNormalProjection>(
      boxes_, radius_, cand, p, radius_, [&](int f, NormalFieldProjection& pr) {
        pr = project_along_normals(surface_->faces[f].kind, X_[f], normals_.face[f], p, inside_tol);
        return pr.valid ? std::abs(pr.d) : std::numeric_limits<double>::infinity();
      });
}

SurfaceProjection SurfaceSearch::closest_brute_force(const Vec3& p, const ProjectionOptions& opt) const {
  if (!ready_) throw std::logic_error("SurfaceSearch: update() not called");
  std::vector<int> all(surface_->faces.size());
  std::iota(all.begin(), all.end(), 0);
  return closest_over(*surface_, X_, boxes_, radius_, all, p, radius_, opt, reject_free_ ? &free_ : nullptr);
}

}  // namespace angio::contact
