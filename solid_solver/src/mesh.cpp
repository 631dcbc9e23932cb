#include "angio/solid/mesh.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string_view>
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
    case FaceType::Quad4:
      std::swap(f.n[1], f.n[3]);
      break;
    case FaceType::Tri3:
      std::swap(f.n[1], f.n[2]);
      break;
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
      // Corners only: the element's corner centroid lies strictly on its side of the plane of the
      // face's corners (a quarter of the opposite vertex's height for a tet). With the mid-edge nodes
      // in, a curved tri6 on a narrow lumen (1 mm elements around a 0.7 mm radius) moves the face's
      // centroid past a thin tet's centroid and the face came out pointing into the wall: every
      // stent point in front of it then counted as 0.1-0.3 mm deep in contact.
      const int nc = num_corners(f.type);
      Vec3d fc = Vec3d::Zero();
      for (int a = 0; a < nc; ++a) fc += X[f.n[a]] / nc;
      const Vec3d A = nc == 3 ? Vec3d((X[f.n[1]] - X[f.n[0]]).cross(X[f.n[2]] - X[f.n[0]]))
                              : Vec3d((X[f.n[2]] - X[f.n[0]]).cross(X[f.n[3]] - X[f.n[1]]));
      if (A.dot(fc - element_centroid(*this, it->second)) < 0) flip(f);
    }
  }
}

double TubeStenosis::lumen_radius(double Ri, double z) const {
  const double d = z - position;
  if (!(severity > 0.0) || std::abs(d) > 0.5 * length) return Ri;
  return Ri * (1.0 - severity * 0.5 * (1.0 + std::cos(2.0 * std::numbers::pi * d / length)));
}

std::vector<double> TubeAxialRefinement::stations(double length, int n_axial) const {
  auto uniform = [](std::vector<double>& z, double a, double b, int n) {
    for (int k = 1; k <= n; ++k) z.push_back(a + (b - a) * k / n);
  };
  std::vector<double> z{0.0};
  if (factor == 1.0) {
    uniform(z, 0.0, length, n_axial);
    return z;
  }
  const double a = from + 0.5 * length, b = to + 0.5 * length, h = length / n_axial;
  if (!(factor >= 1.0) || !(a >= 0.0) || !(a < b) || !(b <= length * (1.0 + 1e-12)))
    throw std::runtime_error("tube: an axial refinement needs factor >= 1 and -length/2 <= from < to <= length/2");
  auto count = [](double n) { return n > 1e-9 ? std::max(1, int(std::lround(n))) : 0; };
  const int n0 = count(a / h), nw = std::max(1, int(std::lround((b - a) / h * factor))), n1 = count((length - b) / h);
  if (n0) uniform(z, 0.0, a, n0);
  uniform(z, a, b, nw);
  if (n1) uniform(z, b, length, n1);
  z.back() = length;
  return z;
}

Mesh make_tube(const TubeSpec& s) {
  if (s.layers.empty()) throw std::runtime_error("tube: no layers");
  if (s.n_circ < 3 || s.n_axial < 1) throw std::runtime_error("tube: n_circ >= 3 and n_axial >= 1 required");
  Mesh m;
  std::vector<double> radii{s.inner_radius};
  std::vector<int> layer_of_shell;
  for (size_t l = 0; l < s.layers.size(); ++l) {
    const auto& L = s.layers[l];
    if (L.n_radial < 1 || !(L.thickness > 0) || !(L.progression > 0))
      throw std::runtime_error("tube: bad layer " + L.name);
    // element j of the layer is progression^j times the first one
    double sum = 0.0;
    for (int j = 0; j < L.n_radial; ++j) sum += std::pow(L.progression, j);
    const double r0 = radii.back();
    double acc = 0.0;
    for (int j = 0; j < L.n_radial; ++j) {
      acc += std::pow(L.progression, j) / sum;
      radii.push_back(j + 1 == L.n_radial ? r0 + L.thickness : r0 + L.thickness * acc);
      layer_of_shell.push_back(int(l));
    }
    m.blocks.push_back({L.name, s.part});
  }
  if (s.centerline && (s.start < -1e-9 || s.start + s.length > s.centerline->length() + 1e-9))
    throw std::runtime_error("tube: " + std::to_string(s.length) + " mm starting at arc length " +
                             std::to_string(s.start) + " mm does not fit on the centerline (" +
                             std::to_string(s.centerline->length()) + " mm)");
  if (s.stenosis.severity > 0.0 && !(s.stenosis.severity < 1.0 && s.stenosis.length > 0.0))
    throw std::runtime_error("tube: a stenosis needs 0 < severity < 1 and a positive length");
  const std::vector<double> zs = s.axial_refinement.stations(s.length, s.n_axial);
  const int nc = s.n_circ, nr = int(radii.size()), na = int(zs.size());
  auto node = [&](int i, int j, int k) { return (k * nr + j) * nc + (i % nc); };
  const double z0 = s.center.z() - 0.5 * s.length;
  const int n1 = s.layers.front().n_radial;  // shells 0..n1 bound the innermost layer
  std::vector<double> r(nr);
  for (int k = 0; k < na; ++k) {
    const double zk = zs[k];  // from end0
    const double rl = s.stenosis.lumen_radius(s.inner_radius, zk - 0.5 * s.length);
    // the innermost layer's shells keep their graded fractions between the lumen and its outer radius
    for (int j = 0; j < nr; ++j)
      r[j] = j <= n1 ? rl + (radii[n1] - rl) * (radii[j] - radii[0]) / (radii[n1] - radii[0]) : radii[j];
    for (int j = 0; j < nr; ++j)
      for (int i = 0; i < nc; ++i) {
        const double th = 2.0 * std::numbers::pi * i / nc;
        if (s.centerline)  // warp of the straight tube (paper §2.4), same map as the stent's
          m.X.push_back(s.centerline->map(th, s.start + zk, r[j]));
        else
          m.X.push_back(Vec3d(s.center.x() + r[j] * std::cos(th), s.center.y() + r[j] * std::sin(th), z0 + zk));
      }
  }
  for (int k = 0; k + 1 < na; ++k)
    for (int j = 0; j + 1 < nr; ++j)
      for (int i = 0; i < nc; ++i) {
        Element e;
        e.type = ElemType::Hex8;
        e.block = layer_of_shell[j];
        // xi: radial, eta: circumferential, zeta: axial -> positive Jacobian
        e.n = {node(i, j, k),     node(i, j + 1, k),     node(i + 1, j + 1, k),     node(i + 1, j, k),
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
// gmsh reader: MSH 4.1, ASCII and binary (gmsh reference manual, "MSH file format", version 4.1).
// One parser serves both encodings: the sections have the same fields in the same order, only the
// encoding of a number differs (a text token, or the raw int / size_t / double in the binary
// file), so the section readers below read fields through MshInput::value<T> and never look at
// the encoding themselves. GmshMeshBuilder is the one place that turns them into the Mesh.
namespace {

// Counts and sizes read from the file are bounded by this and by the bytes left in the file.
constexpr uint64_t kMaxCount = uint64_t(std::numeric_limits<int>::max());  // Mesh indices are int

// The values one record of a section holds at least, to bound a count by the bytes left before
// allocating: in a binary file an int takes 4 bytes, a size_t and a double (data-size) 8; in an
// ASCII file every value takes at least one character and one separator.
struct Record {
  uint64_t ints = 0, sizes = 0, doubles = 0;
};

class MshInput {
 public:
  explicit MshInput(const std::string& path) : path_(path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error(path + ": cannot open mesh file");
    buf_.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    if (f.bad()) throw std::runtime_error(path + ": read error");
  }
  // From the line after the header of $MeshFormat on, numbers are binary in a binary file.
  void set_binary(bool b) { binary_ = binary_file_ = b; }
  // $PhysicalNames is ASCII even in a binary file (gmsh writes it so; manual, MSH 4.1).
  struct AsciiScope {
    explicit AsciiScope(MshInput& in) : in_(in), saved_(in.binary_) { in.binary_ = false; }
    ~AsciiScope() { in_.binary_ = saved_; }
    MshInput& in_;
    bool saved_;
  };

  [[noreturn]] void fail_at(size_t at, const std::string& msg) const {
    if (binary_file_) throw std::runtime_error(path_ + ": " + msg + " at byte offset " + std::to_string(at));
    throw std::runtime_error(path_ + ":" + std::to_string(line_of(at)) + ": " + msg);
  }
  [[noreturn]] void fail(const std::string& msg) const { fail_at(pos_, msg); }

  // Next section header "$Name" (lines outside sections are ignored, as gmsh does); false at the end.
  bool next_section(std::string& name) {
    while (skip_space()) {
      name = line();
      if (name.size() > 1 && name[0] == '$') return true;
    }
    return false;
  }
  // The "$EndName" line closing the section just read.
  void end_section(const std::string& end) {
    const size_t at = pos_;
    const std::string found = skip_space() ? line() : std::string("end of file");
    if (found != end) fail_at(at, "expected " + end + ", found '" + printable(found) + "'");
  }
  // Skips an unknown section $Name up to its "$EndName" line (at a line start; gmsh skips such
  // sections line by line, which also passes over their binary data).
  void skip_section(const std::string& name) {
    const std::string end = "\n$End" + name.substr(1);
    const size_t at = buf_.find(end, pos_ - 1);  // pos_ >= 1: just after the header's newline
    if (at == std::string::npos) fail("section " + name + " has no $End" + name.substr(1));
    pos_ = at + 1;
    line();
  }
  // Rest of the current line (the newline is consumed).
  void skip_line() { line(); }

  template <class T>
  T value(const char* what) {
    return binary_ ? raw<T>(what) : text<T>(what);
  }
  // A count of records that follow: checked against the bytes left before anyone allocates.
  uint64_t count(const char* what, const Record& per_record) {
    const size_t at = pos_;
    const uint64_t n = value<uint64_t>(what);
    const uint64_t bytes = binary_ ? 4 * per_record.ints + 8 * (per_record.sizes + per_record.doubles)
                                   : 2 * (per_record.ints + per_record.sizes + per_record.doubles);
    const uint64_t left = buf_.size() - pos_;
    if (n > kMaxCount || (bytes > 0 && n > left / bytes))
      fail_at(at, std::string(what) + " = " + std::to_string(n) + " does not fit in the " + std::to_string(left) +
                      " bytes left in the file (corrupted or truncated)");
    return n;
  }
  // Skips n values of the given kind (bounded by count() before).
  void skip(const Record& r, uint64_t n) {
    for (uint64_t i = 0; i < n * r.ints; ++i) value<int32_t>("int");
    for (uint64_t i = 0; i < n * r.sizes; ++i) value<uint64_t>("size");
    for (uint64_t i = 0; i < n * r.doubles; ++i) value<double>("double");
  }
  // The next whitespace-separated word (ASCII).
  std::string_view token(const char* what) {
    if (!skip_space()) fail(std::string("unexpected end of file, expected ") + what);
    const size_t at = pos_;
    while (pos_ < buf_.size() && !space(buf_[pos_])) ++pos_;
    return std::string_view(buf_).substr(at, pos_ - at);
  }
  // "name" up to the last quote of the line ($PhysicalNames).
  std::string quoted(const char* what) {
    skip_space();
    const size_t eol = std::min(buf_.find('\n', pos_), buf_.size());
    const size_t close = buf_.rfind('"', eol - 1);
    if (pos_ >= buf_.size() || buf_[pos_] != '"' || close == std::string::npos || close <= pos_)
      fail(std::string("expected a quoted ") + what);
    std::string s = buf_.substr(pos_ + 1, close - pos_ - 1);
    pos_ = close + 1;
    return s;
  }

 private:
  static bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
  bool skip_space() {
    while (pos_ < buf_.size() && space(buf_[pos_])) ++pos_;
    return pos_ < buf_.size();
  }
  std::string line() {
    const size_t eol = std::min(buf_.find('\n', pos_), buf_.size());
    std::string s = buf_.substr(pos_, eol - pos_);
    pos_ = std::min(eol + 1, buf_.size());
    while (!s.empty() && space(s.back())) s.pop_back();
    return s;
  }
  size_t line_of(size_t at) const {
    return 1 + size_t(std::count(buf_.begin(), buf_.begin() + std::min(at, buf_.size()), '\n'));
  }
  static std::string printable(const std::string& s) {
    std::string out;
    for (char c : s.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
    return out;
  }
  template <class T>
  T raw(const char* what) {
    if (buf_.size() - pos_ < sizeof(T)) fail(std::string("unexpected end of file, expected ") + what);
    T v;
    std::memcpy(&v, buf_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  template <class T>
  T text(const char* what) {
    const std::string_view tok = token(what);
    T v{};
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size())
      fail_at(pos_ - tok.size(), std::string("expected ") + what + ", found '" + printable(std::string(tok)) + "'");
    return v;
  }

  std::string path_, buf_;
  size_t pos_ = 0;
  bool binary_ = false, binary_file_ = false;
};

// Node counts of the gmsh element types (manual, "MSH file format": elm-type; the higher-order
// types as gmsh 4.8's getElementProperties reports them); 0: unknown or variable (polygons), such
// elements cannot be skipped in a binary file.
int gmsh_node_count(int type) {
  static constexpr int kNodes[67] = {0,   2,  3,  4,  4,  8,  6,  5,  3,  6,  9,  10, 27, 18, 14, 1,  8,
                                     20,  15, 13, 9,  10, 12, 15, 15, 21, 4,  5,  6,  20, 35, 56, 22, 28,
                                     0,   0,  16, 25, 36, 12, 16, 20, 28, 36, 45, 55, 66, 49, 64, 81, 100,
                                     121, 18, 21, 24, 27, 30, 24, 28, 32, 36, 40, 7,  8,  9,  10, 11};
  if (type >= 0 && type < 67) return kNodes[type];
  if (type == 92) return 64;   // hex64
  if (type == 93) return 125;  // hex125
  return 0;
}

// The element types the solver uses; a volume type counts in 3D entities only, a face type in 2D.
struct GmshElement {
  bool volume = false;
  ElemType elem = ElemType::Hex8;
  FaceType face = FaceType::Quad4;
};
std::optional<GmshElement> supported_element(int type, int entity_dim) {
  std::optional<GmshElement> e;
  switch (type) {
    case 5:
      e = GmshElement{true, ElemType::Hex8, {}};
      break;
    case 4:
      e = GmshElement{true, ElemType::Tet4, {}};
      break;
    case 11:
      e = GmshElement{true, ElemType::Tet10, {}};
      break;
    case 3:
      e = GmshElement{false, {}, FaceType::Quad4};
      break;
    case 2:
      e = GmshElement{false, {}, FaceType::Tri3};
      break;
    case 9:
      e = GmshElement{false, {}, FaceType::Tri6};
      break;
    default:
      return std::nullopt;
  }
  if (entity_dim != (e->volume ? 3 : 2)) return std::nullopt;
  return e;
}

// Collects what the sections say and builds the Mesh: volume physical groups -> blocks, surface
// physical groups -> surface sets (the same for ASCII and binary files).
class GmshMeshBuilder {
 public:
  GmshMeshBuilder(std::string part, std::string prefix, double scale)
      : part_(std::move(part)), prefix_(std::move(prefix)), scale_(scale) {}

  void physical_name(int dim, int tag, std::string name) {
    if (dim >= 0 && dim <= 3) names_[dim][tag] = std::move(name);
  }
  void entity_physical(int dim, int entity, int phys) { entity_phys_[dim][entity].push_back(std::abs(phys)); }
  void node(uint64_t tag, const Vec3d& x) {
    node_index_[tag] = int(m_.X.size());
    m_.X.push_back(scale_ * x);
  }
  std::optional<int> node_index(uint64_t tag) const {
    const auto it = node_index_.find(tag);
    if (it == node_index_.end()) return std::nullopt;
    return it->second;
  }
  // An element of a 3D entity (its first physical group, or a block per entity without one) or a
  // face of a 2D entity (one copy per physical group of the entity).
  void element(const GmshElement& t, int entity, const std::array<int, 10>& nodes) {
    if (t.volume) {
      Element e;
      e.type = t.elem;
      e.block = block_of(entity);
      e.n = nodes;
      m_.elements.push_back(e);
      return;
    }
    Face f;
    f.type = t.face;
    for (int a = 0; a < f.nn(); ++a) f.n[a] = nodes[a];
    for (int g : entity_phys_[2][entity]) m_.surfaces[surface_of(g)].faces.push_back(f);
  }
  Mesh finish(const std::string& path);

 private:
  int block_of(int entity) {
    const auto& groups = entity_phys_[3][entity];
    const int g = groups.empty() ? -entity : groups.front();  // negative: no physical group
    auto it = block_of_phys_.find(g);
    if (it == block_of_phys_.end()) {
      const std::string name = g > 0 && names_[3].count(g) ? names_[3][g] : "volume_" + std::to_string(std::abs(g));
      it = block_of_phys_.emplace(g, int(m_.blocks.size())).first;
      m_.blocks.push_back({name, part_});
    }
    return it->second;
  }
  int surface_of(int g) {
    auto it = surf_of_phys_.find(g);
    if (it == surf_of_phys_.end()) {
      const std::string name = names_[2].count(g) ? names_[2][g] : "surface_" + std::to_string(g);
      it = surf_of_phys_.emplace(g, int(m_.surfaces.size())).first;
      m_.surfaces.push_back({prefix_ + name, {}});
    }
    return it->second;
  }

  std::string part_, prefix_;
  double scale_;
  std::map<int, std::string> names_[4];
  std::map<int, std::vector<int>> entity_phys_[4];
  std::unordered_map<uint64_t, int> node_index_;
  std::map<int, int> block_of_phys_, surf_of_phys_;
  Mesh m_;
};

// Drops the nodes no volume element uses (geometry points etc.) and orients the surfaces.
Mesh GmshMeshBuilder::finish(const std::string& path) {
  Mesh m = std::move(m_);
  if (m.elements.empty()) throw std::runtime_error(path + ": no volume elements (hex8, tet4, tet10) found");
  std::vector<int> used(m.X.size(), -1);
  for (const auto& e : m.elements)
    for (int a = 0; a < e.nn(); ++a) used[e.n[a]] = 0;
  std::vector<Vec3d> X;
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i] == 0) {
      used[i] = int(X.size());
      X.push_back(m.X[i]);
    }
  for (auto& e : m.elements)
    for (int a = 0; a < e.nn(); ++a) e.n[a] = used[e.n[a]];
  for (auto& s : m.surfaces)
    for (auto& f : s.faces)
      for (int a = 0; a < f.nn(); ++a) {
        if (used[f.n[a]] < 0)
          throw std::runtime_error(path + ": surface " + s.name + " has nodes outside the volume mesh");
        f.n[a] = used[f.n[a]];
      }
  m.X = std::move(X);
  try {
    m.orient_surfaces();
  } catch (const std::runtime_error& e) {  // a surface face of no volume element: name the file
    throw std::runtime_error(path + ": " + e.what());
  }
  return m;
}

int entity_dim(MshInput& in) {
  const int d = in.value<int32_t>("entity dimension");
  if (d < 0 || d > 3) in.fail("entity dimension " + std::to_string(d) + " is not 0..3");
  return d;
}

// $MeshFormat: "version file-type data-size", in a binary file followed by the int 1 written in
// binary, which tells the byte order (manual, MSH 4.1, $MeshFormat).
void read_mesh_format(MshInput& in) {
  const std::string version(in.token("version"));
  const int file_type = in.value<int32_t>("file-type");
  const int data_size = in.value<int32_t>("data-size");
  if (version != "4.1")  // 2.x and 4.0 lay the sections out differently
    in.fail("MSH " + version + (file_type == 1 ? " binary" : " ASCII") +
            " is not supported, expected MSH 4.1 ASCII or binary (gmsh: -format msh41, or Mesh.MshFileVersion = 4.1)");
  if (file_type != 0 && file_type != 1)
    in.fail("file-type " + std::to_string(file_type) + ", expected 0 (ASCII) or 1 (binary)");
  in.skip_line();
  if (file_type == 1) {
    if (data_size != 8) in.fail("data-size " + std::to_string(data_size) + ", expected 8 (double)");
    in.set_binary(true);
    const int32_t one = in.value<int32_t>("byte order mark (int 1)");
    if (one == 0x01000000)
      in.fail("the file was written in the opposite byte order to this machine's (write it as ASCII)");
    if (one != 1) in.fail("bad byte order mark " + std::to_string(one) + ", expected the int 1");
  }
  in.end_section("$EndMeshFormat");
}

// $PhysicalNames (ASCII in both encodings): numPhysicalNames, then "dimension tag "name"" lines.
void read_physical_names(MshInput& in, GmshMeshBuilder& b) {
  MshInput::AsciiScope ascii(in);
  const uint64_t n = in.count("numPhysicalNames", Record{.ints = 3});
  for (uint64_t i = 0; i < n; ++i) {
    const int dim = in.value<int32_t>("physical dimension");
    const int tag = in.value<int32_t>("physical tag");
    b.physical_name(dim, tag, in.quoted("physical name"));
  }
  in.end_section("$EndPhysicalNames");
}

// $Entities: numPoints numCurves numSurfaces numVolumes (size_t), then per entity
// tag (int), X Y Z for points or a bounding box min/max XYZ (double), numPhysicalTags (size_t),
// physical tags (int), and for curves/surfaces/volumes numBounding (size_t) and bounding tags (int).
void read_entities(MshInput& in, GmshMeshBuilder& b) {
  uint64_t counts[4];
  for (int d = 0; d < 4; ++d) counts[d] = in.count("number of entities", Record{.ints = 1, .sizes = 1, .doubles = 3});
  for (int d = 0; d < 4; ++d)
    for (uint64_t i = 0; i < counts[d]; ++i) {
      const int tag = in.value<int32_t>("entity tag");
      in.skip(Record{.doubles = d == 0 ? 3u : 6u}, 1);
      const uint64_t np = in.count("numPhysicalTags", Record{.ints = 1});
      for (uint64_t k = 0; k < np; ++k) b.entity_physical(d, tag, in.value<int32_t>("physical tag"));
      if (d > 0) in.skip(Record{.ints = 1}, in.count("number of bounding entities", Record{.ints = 1}));
    }
  in.end_section("$EndEntities");
}

// One entity block of $Nodes: entityDim entityTag parametric (int) numNodesInBlock (size_t),
// the node tags (size_t), then per node x y z (double) and, if parametric, u [v [w]] by entityDim.
void read_node_block(MshInput& in, GmshMeshBuilder& b) {
  const int dim = entity_dim(in);
  in.value<int32_t>("entity tag");
  const int parametric = in.value<int32_t>("parametric");
  const uint64_t params = parametric ? uint64_t(dim) : 0;
  const uint64_t n = in.count("numNodesInBlock", Record{.sizes = 1, .doubles = 3 + params});
  std::vector<uint64_t> tags(n);
  for (auto& t : tags) t = in.value<uint64_t>("node tag");
  for (uint64_t t : tags) {
    Vec3d x;
    for (int k = 0; k < 3; ++k) x(k) = in.value<double>("node coordinate");
    if (!x.allFinite()) in.fail("node " + std::to_string(t) + " has a non-finite coordinate");
    in.skip(Record{.doubles = params}, 1);
    b.node(t, x);
  }
}

// $Nodes: numEntityBlocks numNodes minNodeTag maxNodeTag (size_t), then the entity blocks.
void read_nodes(MshInput& in, GmshMeshBuilder& b) {
  const uint64_t blocks = in.count("numEntityBlocks", Record{.ints = 3, .sizes = 1});
  in.count("numNodes", Record{.sizes = 1, .doubles = 3});
  in.value<uint64_t>("minNodeTag");
  in.value<uint64_t>("maxNodeTag");
  for (uint64_t i = 0; i < blocks; ++i) read_node_block(in, b);
  in.end_section("$EndNodes");
}

// One entity block of $Elements: entityDim entityTag elementType (int) numElementsInBlock
// (size_t), then per element its tag and node tags (size_t).
void read_element_block(MshInput& in, GmshMeshBuilder& b) {
  const int dim = entity_dim(in);
  const int entity = in.value<int32_t>("entity tag");
  const int type = in.value<int32_t>("element type");
  const int nn = gmsh_node_count(type);
  if (nn <= 0) in.fail("element type " + std::to_string(type) + " is unknown (or has a variable node count)");
  const uint64_t n = in.count("numElementsInBlock", Record{.sizes = 1 + uint64_t(nn)});
  const auto kind = supported_element(type, dim);
  for (uint64_t i = 0; i < n; ++i) {
    const uint64_t tag = in.value<uint64_t>("element tag");
    if (!kind) {  // e.g. lines, points: not used by the solver
      in.skip(Record{.sizes = uint64_t(nn)}, 1);
      continue;
    }
    std::array<int, 10> nodes{};
    for (int a = 0; a < nn; ++a) {
      const uint64_t t = in.value<uint64_t>("node tag");
      const auto index = b.node_index(t);
      if (!index) in.fail("element " + std::to_string(tag) + " has the unknown node tag " + std::to_string(t));
      nodes[a] = *index;
    }
    b.element(*kind, entity, nodes);
  }
}

// $Elements: numEntityBlocks numElements minElementTag maxElementTag (size_t), then the blocks.
void read_elements(MshInput& in, GmshMeshBuilder& b) {
  const uint64_t blocks = in.count("numEntityBlocks", Record{.ints = 3, .sizes = 1});
  in.count("numElements", Record{.sizes = 2});
  in.value<uint64_t>("minElementTag");
  in.value<uint64_t>("maxElementTag");
  for (uint64_t i = 0; i < blocks; ++i) read_element_block(in, b);
  in.end_section("$EndElements");
}
}  // namespace

Mesh read_gmsh(const std::string& path, const std::string& part, const std::string& prefix, double scale) {
  MshInput in(path);
  GmshMeshBuilder b(part, prefix, scale);
  std::string sec;
  if (!in.next_section(sec) || sec != "$MeshFormat")
    throw std::runtime_error(path + ": not a gmsh mesh file (no $MeshFormat section first)");
  read_mesh_format(in);
  while (in.next_section(sec)) {
    if (sec == "$PhysicalNames")
      read_physical_names(in, b);
    else if (sec == "$Entities")
      read_entities(in, b);
    else if (sec == "$Nodes")
      read_nodes(in, b);
    else if (sec == "$Elements")
      read_elements(in, b);
    else if (sec == "$PartitionedEntities")  // elements then sit on partition entities without groups
      in.fail("partitioned meshes are not supported, save the mesh before partitioning it");
    else
      in.skip_section(sec);  // $Periodic, $NodeData, $Parametrizations, ...
  }
  return b.finish(path);
}

}  // namespace angio::solid
