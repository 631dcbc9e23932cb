#include "angio/solid/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "angio/geometry/centerline_scene.hpp"
#include "angio/solid/load_scale.hpp"

namespace angio::solid {

namespace {
using scene::Node;

Vec3d v3(const std::array<double, 3>& a) { return Vec3d(a[0], a[1], a[2]); }

LayerMaterial read_material(const Node& n, const std::string& name) {
  n.check_keys();
  LayerMaterial m;
  m.name = name;
  m.matrix.E = n.get<double>("E");
  m.matrix.nu = n.get<double>("nu");
  if (auto v = n.optional("viscous")) {  // paper eqs. B.5–B.8: Q' + Q/tau = beta S'
    v->check_keys();
    ViscousBranch vb;
    vb.tau = v->get<double>("tau");
    vb.beta = v->get<double>("beta");
    // which part of S∞ relaxes: the Neo-Hooke matrix (4C's VISCO_GenMax, the default) or all of it
    vb.acts_on = v->get<std::string>("acts_on") == "isotropic" ? ViscousActsOn::isotropic : ViscousActsOn::all;
    m.viscous = vb;
  }
  if (auto f = n.optional("fibers")) {
    if (!f->is_sequence()) f->fail("a list of fiber families {k1, k2, angle, pair, tension_only}");
    for (size_t i = 0; i < f->size(); ++i) {
      const Node fi = f->at(i);
      fi.check_keys();
      FiberSpec s;
      s.k1 = fi.get<double>("k1");
      s.k2 = fi.get<double>("k2");
      s.angle_deg = fi.get<double>("angle");
      s.pair = fi.get<bool>("pair");
      s.tension_only = fi.get<bool>("tension_only");
      m.fibers.push_back(s);
    }
  }
  return m;
}

Axis read_axis(const Node& parent, const Vec3d& default_origin) {
  Axis a{default_origin, Vec3d::UnitZ()};
  if (auto n = parent.optional("axis")) {
    n->check_keys();
    if (n->has("origin")) a.origin = v3(n->get<std::array<double, 3>>("origin"));
    if (n->has("direction")) {
      a.direction = v3(n->get<std::array<double, 3>>("direction"));
      if (a.direction.norm() < 1e-12) n->child("direction").fail("a non-zero vector");
      a.direction.normalize();
    }
  }
  return a;
}

int shells(const TubeSpec& t) {
  int n = 0;
  for (const auto& l : t.layers) n += l.n_radial;
  return n;
}

// A generated mesh is refused before it is allocated when its assembled tangent alone would not fit
// in the memory available now: 3 DOFs per node, ~81 block-rows of neighbours (hex8) of 3 x 3 values
// and column indices, i.e. ~3 kB per DOF, before any factorization fill. Only a lower bound: a run
// that passes may still need several times more for a direct solver.
void check_memory(const Node& mesh, double nodes) {
  const double dofs = 3.0 * nodes, bytes = dofs * 81.0 * 3.0 * (8.0 + 4.0);
  double avail = 0.0;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char key[64];
    double kb = 0;
    while (std::fscanf(f, "%63s %lf kB\n", key, &kb) == 2)
      if (std::string(key) == "MemAvailable:") avail = kb * 1024.0;
    std::fclose(f);
  }
  if (avail > 0 && bytes > avail) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "a mesh that fits in memory: %.3g nodes (%.3g DOFs) need at least %.3g GB for the tangent "
                  "alone, %.3g GB are available",
                  nodes, dofs, bytes / 1e9, avail / 1e9);
    mesh.fail(msg);
  }
}

// mesh: {generator: tube, ...} or {file: x.msh, ...}; returns the mesh with part-prefixed surfaces.
// `curved` is set for a generated tube warped onto mesh.centerline (paper §2.4, §3.2).
Mesh read_part_mesh(const Node& mesh, const std::string& part, bool layered, Axis& axis,
                    std::optional<geometry::Centerline>& curved) {
  const std::string prefix = part + "_";
  if (mesh.has("file")) {
    mesh.check_keys({"file", "scale", "inner", "outer", "ends", "axis", "centerline"});
    const std::string path = scene::resolve_path(mesh, mesh.get<std::string>("file"));
    Mesh m;
    try {
      m = read_gmsh(path, part, prefix, mesh.get<double>("scale"));
    } catch (const std::exception& e) {
      mesh.child("file").fail(std::string("a readable gmsh 4.1 mesh, ASCII or binary (") + e.what() + ")");
    }
    // an inverted element is refused before anything runs (it would stop the first Newton solve)
    if (const std::string bad = first_invalid_element(m); !bad.empty())
      mesh.child("file").fail("a mesh without inverted elements; in " + path + " " + bad);
    const std::string surfaces = surface_names(m, prefix);
    axis = read_axis(mesh, Vec3d::Zero());
    if (auto cl = mesh.optional("centerline")) {
      // fiber frames from a lumen centerline (patient-specific arteries, paper §4.2.1): [[x, y, z], ...],
      // {points: [...]} or {file: ...} (the key shape of the tube generator and the stent); the
      // summary's lumen stations are then arc lengths along it
      geometry::Centerline c = geometry::centerline_from_scene(*cl);
      set_frames_from_centerline(m, c.points());
      curved = std::move(c);
    } else {
      set_frames_from_axis(m, axis);
    }
    // rename the named surfaces to the canonical names used by the loads
    auto rename = [&](const std::string& key, const std::string& canonical) {
      const std::string given = prefix + mesh.get<std::string>(key);
      for (auto& s : m.surfaces)
        if (s.name == given) {
          s.name = canonical;
          return;
        }
      mesh.child(key).fail("the name of a surface physical group in " + path + " (it has: " + surfaces + ")");
    };
    rename("inner", prefix + "inner");
    if (mesh.has("outer")) {
      rename("outer", prefix + "outer");
      std::set<int> nodes;
      for (const auto& f : m.surface(prefix + "outer")->faces)
        for (int a = 0; a < f.nn(); ++a) nodes.insert(f.n[a]);
      m.node_sets[prefix + "outer"] = std::vector<int>(nodes.begin(), nodes.end());
    }
    if (mesh.has("ends")) {
      const auto ends = mesh.child("ends");
      if (!ends.is_sequence() || ends.size() != 2) ends.fail("a list of two surface names [end0, end1]");
      for (int i = 0; i < 2; ++i) {
        const std::string given = prefix + ends.at(i).as_string();
        bool found = false;
        for (auto& s : m.surfaces)
          if (s.name == given) {
            s.name = prefix + "end" + std::to_string(i);
            found = true;
          }
        if (!found) ends.at(i).fail("the name of a surface physical group in " + path + " (it has: " + surfaces + ")");
      }
    }
    return m;
  }
  mesh.check_keys(layered ? std::initializer_list<const char*>{"generator", "length", "outer_diameter", "n_circ",
                                                               "n_axial", "center", "layers", "centerline", "start",
                                                               "stenosis", "axial_refinement"}
                          : std::initializer_list<const char*>{"generator", "length", "outer_diameter", "wall",
                                                               "n_circ", "n_axial", "center", "centerline", "start"});
  if (mesh.get<std::string>("generator") != "tube") mesh.child("generator").fail("tube");
  TubeSpec t;
  t.part = part;
  t.surface_prefix = prefix;
  t.length = mesh.get<double>("length");
  const double ro = 0.5 * mesh.get<double>("outer_diameter");
  t.n_circ = mesh.get<int>("n_circ");
  t.n_axial = mesh.get<int>("n_axial");
  if (mesh.has("center")) t.center = v3(mesh.get<std::array<double, 3>>("center"));
  double wall = 0.0;
  if (layered) {
    const Node layers = mesh.child("layers", "a list of layers {name, thickness, n_radial} from inside out");
    if (!layers.is_sequence() || layers.size() == 0)
      layers.fail("a non-empty list of layers {name, thickness, n_radial}");
    for (size_t i = 0; i < layers.size(); ++i) {
      const Node l = layers.at(i);
      l.check_keys();
      TubeLayer tl;
      tl.name = l.get<std::string>("name");
      tl.thickness = l.get<double>("thickness");
      tl.n_radial = l.get<int>("n_radial");
      tl.progression = l.get<double>("progression");
      wall += tl.thickness;
      t.layers.push_back(tl);
    }
  } else {
    wall = mesh.get<double>("wall");
    t.layers = {{part, wall, 1}};
  }
  t.inner_radius = ro - wall;
  if (!(t.inner_radius > 0))
    mesh.child("outer_diameter").fail("an outer diameter larger than twice the wall thickness");
  if (auto st = mesh.optional("stenosis")) {  // idealized concentric stenosis (mesh.hpp, TubeStenosis)
    st->check_keys();
    t.stenosis.severity = st->get<double>("severity");  // diameter stenosis; 90 % leaves a 10 % lumen
    t.stenosis.length = st->get<double>("length");
    t.stenosis.position = st->get<double>("position");
    if (std::abs(t.stenosis.position) + 0.5 * t.stenosis.length > 0.5 * t.length)
      st->child("length").fail(
          "a stenosis within the tube (|position| + length/2 <= " + std::to_string(0.5 * t.length) + " mm)");
  }
  if (auto ar = mesh.optional("axial_refinement")) {  // finer elements over the stented segment (mesh.hpp)
    ar->check_keys();
    auto& r = t.axial_refinement;
    r.from = ar->get<double>("from");
    r.to = ar->get<double>("to");
    r.factor = ar->get<double>("factor");
    if (!(r.from < r.to) || r.from < -0.5 * t.length || r.to > 0.5 * t.length)
      ar->child("to").fail("a window within the tube with from < to (both within +-" + std::to_string(0.5 * t.length) +
                           " mm of its centre)");
  }
  if (auto cl = mesh.optional("centerline")) {
    // curved tube: the straight tube warped onto the centerline like the stent (paper §2.4)
    if (mesh.has("center"))
      mesh.child("center").fail("no 'center' with a 'centerline' (a curved tube is placed by centerline and start)");
    geometry::Centerline c = geometry::centerline_from_scene(*cl);
    const std::string source = cl->is_map() && cl->has("file") ? cl->get<std::string>("file") : "the given points";
    if (mesh.has("start")) {
      t.start = mesh.get<double>("start");
      if (t.start + t.length > c.length() + 1e-9)
        mesh.child("start").fail("a start arc length with start + length (" + std::to_string(t.start + t.length) +
                                 " mm) within the centerline (" + source + ", " + std::to_string(c.length()) +
                                 " mm long)");
    } else {
      t.start = 0.5 * (c.length() - t.length);  // centred, as the stent generator's default
      if (t.start < -1e-9)
        mesh.child("length").fail("a tube no longer than the centerline (" + source + ", " +
                                  std::to_string(c.length()) + " mm long), got " + std::to_string(t.length) + " mm");
      t.start = std::max(t.start, 0.0);
    }
    t.centerline = c;
    curved = std::move(c);
  } else if (mesh.has("start")) {
    mesh.child("start").fail("no 'start' without a 'centerline'");
  }
  axis = Axis{t.center, Vec3d::UnitZ()};
  check_memory(mesh,
               double(t.n_circ) * double(t.axial_refinement.stations(t.length, t.n_axial).size()) * (shells(t) + 1.0));
  Mesh m;
  try {
    m = make_tube(t);
  } catch (const std::runtime_error& e) {
    mesh.fail(std::string("a valid tube (") + e.what() + ")");
  }
  if (const std::string bad = first_invalid_element(m); !bad.empty())
    mesh.fail("a tube without inverted elements; " + bad);
  return m;
}

// The peak of value x load curve is checked against the key's declared plausible peak (keys.yaml).
PressureSpec read_pressure(const Node& parent, const std::string& key, const std::string& surface,
                           const scene::LoadCurves& curves, const std::string& label, double max_peak,
                           const char* limit_reason) {
  const scene::ScaledCurve c = scene::scaled_curve(parent, key, curves);
  const auto [lo, hi] = c.range();
  const double peak = std::max(std::abs(lo), std::abs(hi));
  if (peak > max_peak) {
    std::ostringstream m;
    m << "a value whose peak pressure (value x load curve) is at most " << max_peak << " MPa (" << limit_reason
      << "); here it peaks at " << peak << " MPa";
    const scene::Node p = parent.child(key);
    (p.has("value") ? p.child("value") : p).fail(m.str());
  }
  return PressureSpec{surface, c.value, c.curve, label};
}

// fixed: [{surface: end0, components: [x, y, z]}, ...]  (surface names without the part prefix)
void read_fixed(const Node& part, const std::string& prefix, const Mesh& m, std::vector<FixedSpec>& out) {
  const auto f = part.optional("fixed");
  if (!f) return;
  if (!f->is_sequence()) f->fail("a list of {surface, components}");
  for (size_t i = 0; i < f->size(); ++i) {
    const Node e = f->at(i);
    e.check_keys();
    FixedSpec fs;
    fs.surface = prefix + e.get<std::string>("surface");
    if (!m.surface(fs.surface)) e.child("surface").fail("a surface set of this part (e.g. inner, outer, end0, end1)");
    if (e.has("components")) {
      const Node c = e.child("components");
      if (!c.is_sequence()) c.fail("a list of components out of x, y, z");
      for (size_t k = 0; k < c.size(); ++k) {
        const std::string v = c.at(k).as_string();
        if (v != "x" && v != "y" && v != "z") c.at(k).fail("x, y or z");
        fs.components.push_back(v == "x" ? 0 : v == "y" ? 1 : 2);
      }
    } else {
      fs.components = {0, 1, 2};
    }
    out.push_back(fs);
  }
}

// solid.initial_state: {file, parts}: the parts' committed state from a state file of an earlier run.
void read_initial_state(const Node& is, const Node& root, SolidScene& sc) {
  is.check_keys();
  const Node file = is.child("file", "the path of a solid state file (<run>/solid/state.h5 of an earlier run)");
  const std::string path = scene::resolve_path(is, file.as_string());
  StateFile state;
  try {
    state = read_state_file(path);
  } catch (const StateFileError& e) {
    file.fail(std::string("a solid state file: ") + e.what());
  }
  std::vector<std::string> parts;
  if (auto p = is.optional("parts")) {
    if (!p->is_sequence() || p->size() == 0) p->fail("a list of parts of the state file");
    for (size_t i = 0; i < p->size(); ++i) {
      const std::string name = p->at(i).as_string();
      if (std::find(parts.begin(), parts.end(), name) != parts.end()) p->at(i).fail("each part once");
      parts.push_back(name);
    }
  } else {
    for (const auto& ps : state.parts) parts.push_back(ps.name);
  }
  try {
    check_state(state, sc.mesh, parts, sc.materials);
  } catch (const StateFileError& e) {
    (is.has("parts") ? is.child("parts") : file).fail(std::string("parts that fit this scene's mesh: ") + e.what());
  }
  scene::require_start_at(root, sc.time, state.time, path);
  sc.initial_state = std::move(state);
  sc.initial_parts = std::move(parts);
}

// end_springs of a part (balloon, artery): one spring per unit area on each end face (mesh.ends)
void read_end_springs(const Node& part_node, const std::string& part, const Mesh& m, SolidScene& sc) {
  if (!part_node.has("end_springs")) return;
  const double k = part_node.get<double>("end_springs");
  for (const std::string& s : {part + "_end0", part + "_end1"}) {
    if (!m.surface(s)) part_node.child("end_springs").fail(part + " end surfaces (mesh.ends) for the springs");
    sc.springs.push_back({s, k});
  }
}

// balloon: {mesh, material, pressure, end_springs, summary, fixed}
void read_balloon(const Node& b, const scene::LoadCurves& curves, SolidScene& sc) {
  sc.has_balloon = true;
  b.check_keys();
  Axis axis;
  std::optional<geometry::Centerline> curved;
  Mesh m =
      read_part_mesh(b.child("mesh", "a mesh {generator: tube, ...} or {file: ...}"), "balloon", false, axis, curved);
  for (auto& blk : m.blocks) blk.name = m.blocks.size() == 1 ? "balloon" : "balloon_" + blk.name;
  const LayerMaterial mat = read_material(b.child("material", "a material {E, nu, fibers}"), "balloon");
  for (size_t i = 0; i < m.blocks.size(); ++i) {
    LayerMaterial mi = mat;
    mi.name = m.blocks[i].name;
    sc.materials.push_back(mi);
  }
  if (b.has("pressure"))
    sc.pressures.push_back(read_pressure(b, "pressure", "balloon_inner", curves, "balloon_pressure",
                                         scene::keys::peaks::balloon_pressure,
                                         scene::keys::peaks::balloon_pressure_why));
  read_end_springs(b, "balloon", m, sc);
  if (m.node_sets.count("balloon_outer")) {
    DiameterSpec d;
    d.node_set = "balloon_outer";
    d.axis = axis;
    d.centerline = curved;  // curved balloon: arc-length stations
    double smin = std::numeric_limits<double>::max(), smax = -smin;
    for (const auto& x : m.X) {
      const double s = d.station(x);
      smin = std::min(smin, s);
      smax = std::max(smax, s);
    }
    double end_offset = std::min(1.7, 0.25 * (smax - smin));
    if (auto s = b.optional("summary")) {
      s->check_keys();
      if (s->has("end_offset")) end_offset = s->get<double>("end_offset");
      if (!(2 * end_offset < smax - smin))
        s->child("end_offset").fail("an offset smaller than half the balloon length");
    }
    d.s_mid = 0.5 * (smin + smax);
    d.s_end0 = smin + end_offset;
    d.s_end1 = smax - end_offset;
    const int n_spine = curved ? std::max(1, int(std::ceil((smax - smin) / 0.25))) : 1;
    for (int i = 0; i <= n_spine; ++i) {
      const double st = smin + (smax - smin) * i / n_spine;
      sc.balloon_spine.push_back(curved ? Vec3d(curved->point(st)) : Vec3d(axis.origin + st * axis.direction));
    }
    sc.balloon_diameter = d;
  }
  read_fixed(b, "balloon_", m, sc.fixed);
  sc.mesh.append(m);
}

// artery: {mesh, layers, blood_pressure, end_springs, fixed, summary}
void read_artery(const Node& a, const scene::LoadCurves& curves, SolidScene& sc) {
  sc.has_artery = true;
  a.check_keys();
  Axis axis;
  std::optional<geometry::Centerline> curved;
  Mesh m =
      read_part_mesh(a.child("mesh", "a mesh {generator: tube, ...} or {file: ...}"), "artery", true, axis, curved);
  const Node layers = a.child("layers", "a map layer name -> material {E, nu, fibers}");
  if (!layers.is_map()) layers.fail("a map layer name -> material {E, nu, fibers}");
  const Node mesh_node = a.child("mesh");
  const std::string source =
      mesh_node.has("file") ? scene::resolve_path(mesh_node, mesh_node.get<std::string>("file")) : "the generated tube";
  for (const auto& blk : m.blocks) {
    if (!layers.has(blk.name))
      layers.fail("a material for every layer of the artery mesh, missing '" + blk.name + "' (" + source +
                  " has: " + block_names(m) + ")");
    sc.materials.push_back(read_material(layers.child(blk.name), blk.name));
  }
  for (const auto& k : layers.keys())
    if (m.block_index(k) < 0)
      layers.child(k).fail("a layer of the artery mesh; " + source + " has no layer '" + k +
                           "' (it has: " + block_names(m) + ")");
  if (a.has("blood_pressure"))
    sc.pressures.push_back(read_pressure(a, "blood_pressure", "artery_inner", curves, "blood_pressure",
                                         scene::keys::peaks::artery_blood_pressure,
                                         scene::keys::peaks::artery_blood_pressure_why));
  read_end_springs(a, "artery", m, sc);
  // The perivascular tissue (myocardium, epicardial fat) holds a coronary in place: without it a soft
  // curved segment held at its cut ends only bows out of its bend under the blood pressure's resultant
  // p A / R per unit length, amplified by the pressure's effective axial compression p A (a pressurized
  // tube without axial prestretch near Euler buckling; Han, J Biomech 40 (2007) 3672). Springs on the
  // outer surface, as an external tissue support (Moireau et al., Biomech Model Mechanobiol 11 (2012) 1).
  if (a.has("tissue_support")) {
    if (!m.surface("artery_outer"))
      a.child("tissue_support").fail("an artery mesh with an outer surface (mesh.outer) to carry the springs");
    sc.springs.push_back({"artery_outer", a.get<double>("tissue_support")});
  }
  read_fixed(a, "artery_", m, sc.fixed);
  if (m.surface("artery_inner")) {
    DiameterSpec d;
    d.node_set = "artery_inner";
    d.axis = axis;
    d.centerline = curved;
    sc.lumen = d;
  }
  if (auto s = a.optional("summary")) {
    s->check_keys();
    sc.apposition_threshold = s->get<double>("apposition_threshold");
    sc.lumen_max_stations = s->get<int>("lumen_stations");
    sc.stress_average_radius = s->get<double>("stress_average_radius");
  }
  sc.mesh.append(m);
}

// solid: {ranks, partitioner, petsc_options, newton} (initial_state once the mesh is complete)
void read_solver_options(const Node& s, SolidScene& sc) {
  s.check_keys();
  sc.ranks = s.has("ranks") ? s.get<int>("ranks") : 0;
  sc.options.partitioner = s.get<std::string>("partitioner");
  sc.options.petsc_options = s.get<std::string>("petsc_options");
  if (auto n = s.optional("newton")) {
    n->check_keys();
    auto& no = sc.options.newton;
    no.max_iterations = n->get<int>("max_iterations");
    no.rtol = n->get<double>("rtol");
    no.atol = n->get<double>("atol");
    no.line_search = n->get<bool>("line_search");
    no.max_line_search = n->get<int>("max_line_search");
    no.energy_line_search = n->get<std::string>("line_search_merit") == "energy";
    no.verbose = n->get<bool>("verbose");
    no.damping = n->get<double>("damping");
    auto parts = [&](const Node& list) {  // a non-empty list of this scene's parts
      if (!list.is_sequence() || list.size() == 0) list.fail("a list of parts out of balloon, artery");
      std::vector<std::string> out;
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string part = list.at(i).as_string();
        if (!((part == "balloon" && sc.has_balloon) || (part == "artery" && sc.has_artery)))
          list.at(i).fail(std::string("a part of this scene (") + (sc.has_balloon ? "balloon" : "") +
                          (sc.has_balloon && sc.has_artery ? ", " : "") + (sc.has_artery ? "artery" : "") + ")");
        out.push_back(part);
      }
      return out;
    };
    if (auto dp = n->optional("damping_parts")) {
      if (!(no.damping > 0)) dp->fail("no damping_parts without damping > 0");
      no.damping_parts = parts(*dp);
    }
    no.reuse_preconditioner = n->get<int>("reuse_preconditioner");
    if (auto rp = n->optional("reuse_parts")) {
      if (no.reuse_preconditioner <= 0)
        rp->fail("solid.newton.reuse_preconditioner > 0 (the Krylov iterations that renew the kept splits)");
      no.reuse_parts = parts(*rp);
    }
    no.modified = n->get<std::string>("tangent") == "modified";
    no.max_contraction = n->get<double>("max_contraction");
    no.continuation = n->get<int>("continuation");
    if (no.continuation == 1)
      n->child("continuation").fail("0 (off) or the finest sub-increment as a fraction 1/N, N from 2 to 1024");
    no.extrapolate = n->get<std::string>("prediction") == "extrapolate";
    if (n->optional("max_contraction") && !no.modified)
      n->child("max_contraction")
          .fail("solid.newton.tangent: modified (max_contraction applies to the modified Newton only)");
    if (no.modified && no.reuse_preconditioner > 0)
      n->child("reuse_preconditioner")
          .fail("0 with tangent: modified (the modified Newton keeps the whole factorization)");
  }
}

}  // namespace

SolidScene read_solid_scene(const Node& root) {
  SolidScene sc;
  sc.time = scene::time_settings(root);
  const auto curves = scene::load_curves(root);
  sc.output = scene::output_settings(root);

  if (auto b = root.optional("balloon")) read_balloon(*b, curves, sc);
  if (auto a = root.optional("artery")) read_artery(*a, curves, sc);
  if (!sc.has_balloon && !sc.has_artery)
    root.fail("a scene with a 'balloon:' and/or 'artery:' section for the solid solver");
  for (size_t i = 0; i < sc.mesh.blocks.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (sc.mesh.blocks[i].name == sc.mesh.blocks[j].name)
        root.fail("unique block names (balloon and artery both have a block '" + sc.mesh.blocks[i].name + "')");

  if (auto s = root.optional("solid")) read_solver_options(*s, sc);
  if (auto s = root.optional("solid"))
    if (auto is = s->optional("initial_state")) read_initial_state(*is, root, sc);
  // The Newton stops at ||r|| <= atol whatever the load; an atol of the order of the loads' own norm
  // accepts a loaded step before anything moves (found by the Newton-tolerance ladder of bench/work_precision.py:
  // atol 1 N on the straight scene, the balloon never inflated and the run ended "ok").
  std::vector<std::pair<std::string, double>> peaks;
  for (const auto& p : sc.pressures) {
    double c = 0.0;
    for (const auto& [t, v] : p.curve.points()) c = std::max(c, std::abs(v));
    peaks.emplace_back(p.surface, p.value * c);
  }
  sc.peak_load_norm = pressure_load_norm(sc.mesh, peaks);
  const double atol = sc.options.newton.atol;
  if (sc.peak_load_norm > 0.0 && atol >= kMaxAtolOfLoad * sc.peak_load_norm) {
    std::ostringstream m;
    m << "an absolute residual tolerance well below the norm of the peak pressure load (" << sc.peak_load_norm
      << " N on the reference mesh): at most " << kMaxAtolOfLoad * sc.peak_load_norm
      << " N, the shipped scenes use about 1e-4 of it; a tolerance this loose accepts a loaded step before it moves";
    const auto s = root.optional("solid");
    const auto n = s ? s->optional("newton") : std::nullopt;
    if (n && n->has("atol")) n->child("atol").fail(m.str());
    m << " (solid.newton.atol is not given: its default " << atol << " N)";
    root.fail(m.str());
  }
  return sc;
}

}  // namespace angio::solid
