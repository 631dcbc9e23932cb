#include "angio/solid/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace angio::solid {

int Mesh::block_index(const std::string& name) const {
  for (size_t i = 0; i < blocks.size(); ++i)
    if (blocks[i].name == name) return int(i);
  return -1;
}

const SurfaceSet* Mesh::surface(const std::string& name) const {
  for (const auto& s : surfaces)
    if (s.name == name) return &s;
  return nullptr;
}

void Mesh::append(const Mesh& o) {
  const int off = int(X.size());
  const int boff = int(blocks.size());
  X.insert(X.end(), o.X.begin(), o.X.end());
  blocks.insert(blocks.end(), o.blocks.begin(), o.blocks.end());
  for (auto e : o.elements) {
    for (int a = 0; a < e.nn(); ++a) e.n[a] += off;
    e.block += boff;
    elements.push_back(e);
  }
  for (auto s : o.surfaces) {
    for (auto& f : s.faces)
      for (int a = 0; a < f.nn(); ++a) f.n[a] += off;
    surfaces.push_back(std::move(s));
  }
  if (!o.frames.empty() || !frames.empty()) {
    if (frames.size() != elements.size() - o.elements.size() || o.frames.size() != o.elements.size())
      throw std::runtime_error("mesh append: frames must be given for all elements or none");
    frames.insert(frames.end(), o.frames.begin(), o.frames.end());
  }
  for (auto [name, nodes] : o.node_sets) {
    for (auto& n : nodes) n += off;
    node_sets[name] = nodes;
  }
}

Vec3d element_centroid(const Mesh& m, int e) {
  const auto& el = m.elements[e];
  Vec3d c = Vec3d::Zero();
  const int nc = el.type == ElemType::Hex8 ? 8 : 4;  // corners only
  for (int a = 0; a < nc; ++a) c += m.X[el.n[a]];
  return c / nc;
}

Frame element_frame(const Mesh& m, int e, const Axis& axis) {
  const Vec3d c = element_centroid(m, e);
  const Vec3d ez = axis.direction.normalized();
  Vec3d r = c - axis.origin;
  r -= r.dot(ez) * ez;
  if (r.norm() < 1e-12) r = ez.unitOrthogonal();
  Frame f;
  f.radial = r.normalized();
  f.axial = ez;
  f.circumferential = ez.cross(f.radial).normalized();
  return f;
}

void set_frames_from_axis(Mesh& m, const Axis& axis) {
  m.frames.resize(m.elements.size());
  for (size_t e = 0; e < m.elements.size(); ++e) m.frames[e] = element_frame(m, int(e), axis);
}

void set_frames_from_centerline(Mesh& m, const std::vector<Vec3d>& cl) {
  if (cl.size() < 2) throw std::runtime_error("centerline: at least two points required");
  m.frames.resize(m.elements.size());
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const Vec3d c = element_centroid(m, int(e));
    double best = std::numeric_limits<double>::max();
    Vec3d p_best = cl[0], t_best = (cl[1] - cl[0]).normalized();
    for (size_t i = 0; i + 1 < cl.size(); ++i) {
      const Vec3d d = cl[i + 1] - cl[i];
      const double L2 = d.squaredNorm();
      if (L2 <= 0) continue;
      const double s = std::clamp((c - cl[i]).dot(d) / L2, 0.0, 1.0);
      const Vec3d p = cl[i] + s * d;
      const double dist = (c - p).squaredNorm();
      if (dist < best) {
        best = dist;
        p_best = p;
        t_best = d.normalized();
      }
    }
    m.frames[e] = element_frame(m, int(e), Axis{p_best, t_best});
  }
}

void set_frames_from_curved_axis(Mesh& m, const geometry::Centerline& cl) {
  m.frames.resize(m.elements.size());
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const auto p = cl.closest(element_centroid(m, int(e)));
    Frame f;
    f.axial = p.frame.tangent;
    f.radial = p.distance > 1e-12 ? p.radial : p.frame.normal1;
    f.circumferential = f.axial.cross(f.radial).normalized();
    m.frames[e] = f;
  }
}

namespace {
using Key = std::array<int, 3>;
struct KeyHash {
  size_t operator()(const Key& k) const {
    return (size_t(k[0]) * 73856093u) ^ (size_t(k[1]) * 19349663u) ^ (size_t(k[2]) * 83492791u);
  }
};
Key corner_key(const int* n, int nc) {
  std::array<int, 4> c{};
  for (int a = 0; a < nc; ++a) c[a] = n[a];
  // insertion sort (nc <= 4)
  for (int a = 1; a < nc; ++a)
    for (int b = a; b > 0 && c[b - 1] > c[b]; --b) std::swap(c[b - 1], c[b]);
  return {c[0], c[1], c[2]};  // three smallest corners identify a face
}
void flip(Face& f) {
  switch (f.type) {
    case FaceType::Quad4: std::swap(f.n[1], f.n[3]); break;
    case FaceType::Tri3: std::swap(f.n[1], f.n[2]); break;
    case FaceType::Tri6:
      std::swap(f.n[1], f.n[2]);
      std::swap(f.n[3], f.n[5]);
      break;
  }
}
}  // namespace

void Mesh::orient_surfaces() {
  std::unordered_map<Key, int, KeyHash> owner;
  for (int e = 0; e < int(elements.size()); ++e) {
    const auto& el = elements[e];
    for (const auto& lf : local_faces(el.type)) {
      int n[4];
      const int nc = num_corners(lf.type);
      for (int a = 0; a < nc; ++a) n[a] = el.n[lf.nodes[a]];
      owner.emplace(corner_key(n, nc), e);
    }
  }
  for (auto& s : surfaces) {
    for (auto& f : s.faces) {
      const auto it = owner.find(corner_key(f.n.data(), num_corners(f.type)));
      if (it == owner.end())
        throw std::runtime_error("surface '" + s.name + "': a face is not a face of any volume element");
      Eigen::MatrixXd Xf(f.nn(), 3);
      Vec3d fc = Vec3d::Zero();
      for (int a = 0; a < f.nn(); ++a) {
        Xf.row(a) = X[f.n[a]].transpose();
        fc += X[f.n[a]];
      }
      fc /= f.nn();
      const Vec3d A = face_area_vector(f.type, Xf);
      if (A.dot(fc - element_centroid(*this, it->second)) < 0) flip(f);
    }
  }
}

Mesh make_tube(const TubeSpec& s) {
  if (s.layers.empty()) throw std::runtime_error("tube: no layers");
  if (s.n_circ < 3 || s.n_axial < 1) throw std::runtime_error("tube: n_circ >= 3 and n_axial >= 1 required");
  Mesh m;
  std::vector<double> radii{s.inner_radius};
  std::vector<int> layer_of_shell;
  for (size_t l = 0; l < s.layers.size(); ++l) {
    const auto& L = s.layers[l];
    if (L.n_radial < 1 || !(L.thickness > 0)) throw std::runtime_error("tube: bad layer " + L.name);
    for (int j = 0; j < L.n_radial; ++j) {
      radii.push_back(radii.back() + L.thickness / L.n_radial);
      layer_of_shell.push_back(int(l));
    }
    m.blocks.push_back({L.name, s.part});
  }
  if (s.centerline && (s.start < -1e-9 || s.start + s.length > s.centerline->length() + 1e-9))
    throw std::runtime_error("tube: " + std::to_string(s.length) + " mm starting at arc length " +
                             std::to_string(s.start) + " mm does not fit on the centerline (" +
                             std::to_string(s.centerline->length()) + " mm)");
  const int nc = s.n_circ, nr = int(radii.size()), na = s.n_axial + 1;
  auto node = [&](int i, int j, int k) { return (k * nr + j) * nc + (i % nc); };
  const double z0 = s.center.z() - 0.5 * s.length;
  for (int k = 0; k < na; ++k)
    for (int j = 0; j < nr; ++j)
      for (int i = 0; i < nc; ++i) {
        const double th = 2.0 * std::numbers::pi * i / nc;
        if (s.centerline)  // warp of the straight tube (paper §2.4), same map as the stent's
          m.X.push_back(s.centerline->map(th, s.start + s.length * k / s.n_axial, radii[j]));
        else
          m.X.push_back(Vec3d(s.center.x() + radii[j] * std::cos(th), s.center.y() + radii[j] * std::sin(th),
                              z0 + s.length * k / s.n_axial));
      }
  for (int k = 0; k + 1 < na; ++k)
    for (int j = 0; j + 1 < nr; ++j)
      for (int i = 0; i < nc; ++i) {
        Element e;
        e.type = ElemType::Hex8;
        e.block = layer_of_shell[j];
        // xi: radial, eta: circumferential, zeta: axial -> positive Jacobian
        e.n = {node(i, j, k), node(i, j + 1, k), node(i + 1, j + 1, k), node(i + 1, j, k),
               node(i, j, k + 1), node(i, j + 1, k + 1), node(i + 1, j + 1, k + 1), node(i + 1, j, k + 1)};
        m.elements.push_back(e);
      }
  SurfaceSet inner{s.surface_prefix + "inner", {}}, outer{s.surface_prefix + "outer", {}},
      end0{s.surface_prefix + "end0", {}}, end1{s.surface_prefix + "end1", {}};
  for (int k = 0; k + 1 < na; ++k)
    for (int i = 0; i < nc; ++i) {
      Face f;
      f.type = FaceType::Quad4;
      f.n = {node(i, 0, k), node(i + 1, 0, k), node(i + 1, 0, k + 1), node(i, 0, k + 1), 0, 0};
      inner.faces.push_back(f);
      f.n = {node(i, nr - 1, k), node(i + 1, nr - 1, k), node(i + 1, nr - 1, k + 1), node(i, nr - 1, k + 1), 0, 0};
      outer.faces.push_back(f);
    }
  for (int j = 0; j + 1 < nr; ++j)
    for (int i = 0; i < nc; ++i) {
      Face f;
      f.type = FaceType::Quad4;
      f.n = {node(i, j, 0), node(i + 1, j, 0), node(i + 1, j + 1, 0), node(i, j + 1, 0), 0, 0};
      end0.faces.push_back(f);
      const int k = na - 1;
      f.n = {node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k), 0, 0};
      end1.faces.push_back(f);
    }
  m.surfaces = {inner, outer, end0, end1};
  std::vector<int> outer_nodes, inner_nodes;
  for (int k = 0; k < na; ++k)
    for (int i = 0; i < nc; ++i) {
      outer_nodes.push_back(node(i, nr - 1, k));
      inner_nodes.push_back(node(i, 0, k));
    }
  m.node_sets[s.surface_prefix + "outer"] = outer_nodes;
  m.node_sets[s.surface_prefix + "inner"] = inner_nodes;
  m.orient_surfaces();
  if (s.centerline)
    set_frames_from_curved_axis(m, *s.centerline);  // longitudinal fibers along the curved axis
  else
    set_frames_from_axis(m, Axis{s.center, Vec3d::UnitZ()});
  return m;
}

// ---------------------------------------------------------------------------------------------
// gmsh reader
namespace {
struct Reader {
  std::ifstream in;
  std::string path;
  int line = 0;
  std::istringstream ls;
  [[noreturn]] void fail(const std::string& msg) const {
    throw std::runtime_error(path + ":" + std::to_string(line) + ": " + msg);
  }
  bool next() {
    std::string s;
    while (std::getline(in, s)) {
      ++line;
      if (!s.empty() && s.back() == '\r') s.pop_back();
      if (s.find_first_not_of(" \t") == std::string::npos) continue;
      ls.clear();
      ls.str(s);
      return true;
    }
    return false;
  }
  std::string word() {
    std::string w;
    if (!(ls >> w)) fail("unexpected end of line");
    return w;
  }
  template <class T>
  T get(const char* what) {
    T v;
    if (!(ls >> v)) fail(std::string("expected ") + what);
    return v;
  }
  void need_next(const char* what) {
    if (!next()) fail(std::string("unexpected end of file, expected ") + what);
  }
};
}  // namespace

Mesh read_gmsh(const std::string& path, const std::string& part, const std::string& prefix, double scale) {
  Reader r;
  r.path = path;
  r.in.open(path);
  if (!r.in) throw std::runtime_error(path + ": cannot open mesh file");
  std::map<int, std::string> phys_names[4];
  std::map<int, std::vector<int>> entity_phys[4];
  std::unordered_map<long, int> node_index;
  Mesh m;
  std::map<int, int> block_of_phys;
  std::map<int, int> surf_of_phys;
  bool have_format = false;
  while (r.next()) {
    const std::string sec = r.word();
    if (sec == "$MeshFormat") {
      r.need_next("version");
      const double ver = r.get<double>("version");
      const int ft = r.get<int>("file type");
      if (ver < 4.0 || ver >= 5.0) r.fail("unsupported msh version " + std::to_string(ver) + ", expected 4.x");
      if (ft != 0) r.fail("binary msh files are not supported, expected ASCII (file-type 0)");
      have_format = true;
      r.need_next("$EndMeshFormat");
    } else if (sec == "$PhysicalNames") {
      r.need_next("count");
      const int n = r.get<int>("number of physical names");
      for (int i = 0; i < n; ++i) {
        r.need_next("physical name");
        const int dim = r.get<int>("dimension");
        const int tag = r.get<int>("tag");
        std::string rest;
        std::getline(r.ls, rest);
        const auto a = rest.find('"'), b = rest.rfind('"');
        if (a == std::string::npos || b == a) r.fail("expected quoted physical name");
        if (dim >= 0 && dim <= 3) phys_names[dim][tag] = rest.substr(a + 1, b - a - 1);
      }
      r.need_next("$EndPhysicalNames");
    } else if (sec == "$Entities") {
      r.need_next("entity counts");
      int cnt[4];
      for (int d = 0; d < 4; ++d) cnt[d] = r.get<int>("entity count");
      for (int d = 0; d < 4; ++d)
        for (int i = 0; i < cnt[d]; ++i) {
          r.need_next("entity");
          const int tag = r.get<int>("entity tag");
          for (int k = 0; k < (d == 0 ? 3 : 6); ++k) r.get<double>("bounding box");
          const int np = r.get<int>("number of physical tags");
          for (int k = 0; k < np; ++k) entity_phys[d][tag].push_back(std::abs(r.get<int>("physical tag")));
        }
      r.need_next("$EndEntities");
    } else if (sec == "$Nodes") {
      r.need_next("node header");
      const long nblocks = r.get<long>("numEntityBlocks");
      r.get<long>("numNodes");
      for (long b = 0; b < nblocks; ++b) {
        r.need_next("node block");
        r.get<int>("entityDim");
        r.get<int>("entityTag");
        const int param = r.get<int>("parametric");
        const long n = r.get<long>("numNodesInBlock");
        std::vector<long> tags(n);
        for (long i = 0; i < n; ++i) {
          r.need_next("node tag");
          tags[i] = r.get<long>("node tag");
        }
        for (long i = 0; i < n; ++i) {
          r.need_next("node coordinates");
          Vec3d x;
          x.x() = r.get<double>("x");
          x.y() = r.get<double>("y");
          x.z() = r.get<double>("z");
          (void)param;
          node_index[tags[i]] = int(m.X.size());
          m.X.push_back(scale * x);
        }
      }
      r.need_next("$EndNodes");
    } else if (sec == "$Elements") {
      r.need_next("element header");
      const long nblocks = r.get<long>("numEntityBlocks");
      r.get<long>("numElements");
      for (long b = 0; b < nblocks; ++b) {
        r.need_next("element block");
        const int dim = r.get<int>("entityDim");
        const int etag = r.get<int>("entityTag");
        const int gtype = r.get<int>("elementType");
        const long n = r.get<long>("numElementsInBlock");
        int nn = 0;
        bool vol = false;
        ElemType et = ElemType::Hex8;
        FaceType ft = FaceType::Quad4;
        switch (gtype) {
          case 5: nn = 8; vol = true; et = ElemType::Hex8; break;
          case 4: nn = 4; vol = true; et = ElemType::Tet4; break;
          case 11: nn = 10; vol = true; et = ElemType::Tet10; break;
          case 3: nn = 4; ft = FaceType::Quad4; break;
          case 2: nn = 3; ft = FaceType::Tri3; break;
          case 9: nn = 6; ft = FaceType::Tri6; break;
          default: nn = -1;
        }
        const auto& phys = entity_phys[std::clamp(dim, 0, 3)][etag];
        for (long i = 0; i < n; ++i) {
          r.need_next("element");
          if (nn < 0 || (vol && dim != 3) || (!vol && dim != 2)) continue;
          r.get<long>("element tag");
          std::array<int, 10> nodes{};
          for (int a = 0; a < nn; ++a) {
            const long t = r.get<long>("node tag");
            const auto it = node_index.find(t);
            if (it == node_index.end()) r.fail("unknown node tag " + std::to_string(t));
            nodes[a] = it->second;
          }
          if (vol) {
            std::vector<int> groups = phys;
            if (groups.empty()) groups.push_back(-etag);  // no physical group: block per entity
            const int g = groups.front();
            auto bit = block_of_phys.find(g);
            if (bit == block_of_phys.end()) {
              std::string bname = g > 0 && phys_names[3].count(g) ? phys_names[3][g]
                                                                  : "volume_" + std::to_string(std::abs(g));
              bit = block_of_phys.emplace(g, int(m.blocks.size())).first;
              m.blocks.push_back({bname, part});
            }
            Element e;
            e.type = et;
            e.block = bit->second;
            e.n = nodes;
            m.elements.push_back(e);
          } else {
            for (int g : phys) {
              auto sit = surf_of_phys.find(g);
              if (sit == surf_of_phys.end()) {
                std::string sname = phys_names[2].count(g) ? phys_names[2][g] : "surface_" + std::to_string(g);
                sit = surf_of_phys.emplace(g, int(m.surfaces.size())).first;
                m.surfaces.push_back({prefix + sname, {}});
              }
              Face f;
              f.type = ft;
              for (int a = 0; a < nn; ++a) f.n[a] = nodes[a];
              m.surfaces[sit->second].faces.push_back(f);
            }
          }
        }
      }
      r.need_next("$EndElements");
    } else if (!sec.empty() && sec[0] == '$' && sec.rfind("$End", 0) != 0) {
      // skip unknown section
      const std::string end = "$End" + sec.substr(1);
      bool found = false;
      while (r.next()) {
        std::string w;
        r.ls >> w;
        if (w == end) {
          found = true;
          break;
        }
      }
      if (!found) r.fail("missing " + end);
    }
  }
  if (!have_format) throw std::runtime_error(path + ": not a gmsh file (no $MeshFormat)");
  if (m.elements.empty()) throw std::runtime_error(path + ": no volume elements (hex8, tet4, tet10) found");
  // drop unreferenced nodes (geometry points etc.)
  std::vector<int> used(m.X.size(), -1);
  int cnt = 0;
  for (const auto& e : m.elements)
    for (int a = 0; a < e.nn(); ++a)
      if (used[e.n[a]] < 0) used[e.n[a]] = 0;
  std::vector<Vec3d> X2;
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i] == 0) {
      used[i] = cnt++;
      X2.push_back(m.X[i]);
    }
  for (auto& e : m.elements)
    for (int a = 0; a < e.nn(); ++a) e.n[a] = used[e.n[a]];
  for (auto& s : m.surfaces)
    for (auto& f : s.faces)
      for (int a = 0; a < f.nn(); ++a) {
        if (used[f.n[a]] < 0) throw std::runtime_error(path + ": surface " + s.name + " has nodes outside the volume mesh");
        f.n[a] = used[f.n[a]];
      }
  m.X = std::move(X2);
  // fix negative-Jacobian volume elements by reporting them
  m.orient_surfaces();
  return m;
}

}  // namespace angio::solid
