#include "angio/beam/scene.hpp"

#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

#include "angio/geometry/centerline_scene.hpp"

namespace angio::beam {

using scene::Node;
using scene::SceneError;

namespace {

Vec3 v3(const std::array<double, 3>& a) { return Vec3(a[0], a[1], a[2]); }

Curve to_curve(const scene::LoadCurve& c) {
  return [c](double t) { return c.value(t); };
}

Section read_section(const Node& st) {
  const Node mat = st.child("material", "a map {E, nu or G}");
  mat.check_keys();
  const double E = mat.get<double>("E");
  double nu, G;
  if (mat.has("G")) {
    G = mat.get<double>("G");
    nu = E / (2 * G) - 1;
  } else {
    nu = mat.get<double>("nu");
    G = E / (2 * (1 + nu));
  }
  const Node sec = st.child("section", "a map {radius} or {A, I2, I3, J}");
  sec.check_keys();
  Section s;
  if (sec.has("radius")) {
    const double R = sec.get<double>("radius");
    double k = -1;
    if (sec.has("shear_factors")) {
      auto f = sec.get<std::vector<double>>("shear_factors");
      if (f.size() != 2 || !(f[0] > 0) || f[0] != f[1])
        sec.child("shear_factors").fail("two equal positive shear factors for a circular section");
      k = f[0];
    }
    s = circular_section(E, nu, R, k);
  } else {
    double k2 = 1, k3 = 1;
    if (sec.has("shear_factors")) {
      auto f = sec.get<std::vector<double>>("shear_factors");
      if (f.size() != 2 || !(f[0] > 0) || !(f[1] > 0))
        sec.child("shear_factors").fail("two positive shear factors [k2, k3]");
      k2 = f[0];
      k3 = f[1];
    }
    s = general_section(E, G, sec.get<double>("A"), sec.get<double>("I2"), sec.get<double>("I3"), sec.get<double>("J"),
                        k2, k3);
  }
  if (sec.has("contact_radius")) s.contact_radius = sec.get<double>("contact_radius");
  if (auto pl = st.optional("plasticity")) {
    pl->check_keys();
    if (std::abs(s.EI2 - s.EI3) > 1e-12 * s.EI2) pl->fail("a circular section (I2 == I3) for bending plasticity");
    const double My0 = pl->get<double>("yield_moment");
    const double Eep = pl->get<double>("tangent_modulus");
    if (!(Eep < E)) pl->child("tangent_modulus").fail("a value below E");
    add_bending_plasticity(s, E, My0, Eep);
  }
  return s;
}

std::vector<int> node_list(const Node& n, const std::string& key, int num_nodes) {
  std::vector<int> out;
  const Node c = n.child(key, "a list of node indices");
  if (c.is_scalar()) {
    if (c.as_string() == "all") {
      for (int i = 0; i < num_nodes; ++i) out.push_back(i);
      return out;
    }
    const long v = c.as_integer();
    if (v < -num_nodes || v >= num_nodes)
      c.fail("a node index in [" + std::to_string(-num_nodes) + ", " + std::to_string(num_nodes - 1) + "]");
    out.push_back(static_cast<int>(v < 0 ? v + num_nodes : v));
    return out;
  }
  for (std::size_t i = 0; i < c.size(); ++i) {
    const long v = c.at(i).as_integer();
    if (v < -num_nodes || v >= num_nodes)
      c.at(i).fail("a node index in [" + std::to_string(-num_nodes) + ", " + std::to_string(num_nodes - 1) +
                   "] (negative counts from the end)");
    out.push_back(static_cast<int>(v < 0 ? v + num_nodes : v));
  }
  return out;
}

std::vector<int> element_list(const Node& n, const std::string& key, int ne) {
  std::vector<int> out;  // empty = all
  if (!n.has(key)) return out;
  const Node c = n.child(key);
  if (c.is_scalar()) {
    if (c.as_string() != "all") c.fail("'all' or a list of element indices");
    return out;
  }
  for (std::size_t i = 0; i < c.size(); ++i) {
    const long v = c.at(i).as_integer();
    if (v < 0 || v >= ne) c.at(i).fail("an element index in [0, " + std::to_string(ne - 1) + "]");
    out.push_back(static_cast<int>(v));
  }
  return out;
}

std::vector<Vec3> read_points(const Node& n) {
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n.size(); ++i) pts.push_back(v3(n.at(i).as_vec3()));
  if (pts.size() < 2) n.fail("at least two points [x, y, z]");
  return pts;
}

// The stent's nodes and elements: stent.generator, stent.lines or stent.nodes/elements; returns the
// generator's default fixation nodes (the middle ring's bottom crowns).
std::vector<int> read_geometry(const Node& st, int sec, BeamScene& bs) {
  BeamModel& m = *bs.model;
  std::vector<int> fixation_default;
  if (auto g = st.optional("generator")) {
    if (st.has("nodes") || st.has("lines")) st.fail("either generator or nodes/elements/lines, not both");
    g->check_keys();
    g->get<std::string>("type");  // corrugated_rings, the one generator
    StentParameters p;
    p.rings = g->get<int>("rings");  // at most 1000 rings, a 1.5 m stent
    p.crowns = g->get<int>("crowns");
    p.crimped_diameter = g->get<double>("crimped_diameter");
    p.strut_height = g->get<double>("strut_height");
    p.ring_pitch = g->get<double>("ring_pitch");
    p.connectors = g->get<int>("connectors");
    if (p.connectors > p.crowns) g->child("connectors").fail("at most `crowns` connectors");
    p.elements_per_strut = g->get<int>("elements_per_strut");
    p.elements_per_connector = g->get<int>("elements_per_connector");
    p.start = g->get<double>("start");
    // centerline: {file} | {points}: the same key shape as balloon/artery.mesh.centerline, so
    // one centerline file places stent and balloon on the same curved axis (paper §2.4)
    std::optional<geometry::Centerline> cl;
    if (auto c = g->optional("centerline")) cl = geometry::centerline_from_scene(*c);
    try {
      bs.stent = cl ? generate_corrugated_rings(p, *cl) : generate_corrugated_rings(p);
    } catch (const std::invalid_argument& e) {
      g->fail(std::string("consistent stent parameters (") + e.what() + ")");
    }
    bs.generated_stent = true;
    for (const auto& x : bs.stent->nodes) m.add_node(x);
    for (size_t e = 0; e < bs.stent->elements.size(); ++e)
      m.add_element(bs.stent->elements[e][0], bs.stent->elements[e][1], sec, bs.stent->element_up[e]);
    m.axis.points = bs.stent->axis;
    fixation_default = bs.stent->fixation_nodes;
  } else if (auto ln = st.optional("lines")) {
    // straight lines subdivided into elements; coincident end points are merged
    Vec3 up = Vec3::Zero();
    if (st.has("up")) up = v3(st.get<std::array<double, 3>>("up"));
    auto node_at = [&](const Vec3& x) {
      for (int i = 0; i < m.num_nodes(); ++i)
        if ((m.reference_position(i) - x).norm() < 1e-10) return i;
      return m.add_node(x);
    };
    for (std::size_t i = 0; i < ln->size(); ++i) {
      const Node l = ln->at(i);
      l.check_keys();
      const Vec3 a = v3(l.get<std::array<double, 3>>("from")), b = v3(l.get<std::array<double, 3>>("to"));
      const int n = l.get<int>("elements");
      if ((b - a).norm() <= 0) l.fail("a line of non-zero length");
      int prev = node_at(a);
      for (int k = 1; k <= n; ++k) {
        const int cur = k == n ? node_at(b) : m.add_node(a + (b - a) * (static_cast<double>(k) / n));
        m.add_element(prev, cur, sec, up);
        prev = cur;
      }
    }
  } else {
    const Node nodes = st.child("nodes", "generator, lines or nodes/elements");
    for (std::size_t i = 0; i < nodes.size(); ++i) m.add_node(v3(nodes.at(i).as_vec3()));
    const Node els = st.child("elements", "a list of [node1, node2]");
    Vec3 up = Vec3::Zero();
    if (st.has("up")) up = v3(st.get<std::array<double, 3>>("up"));
    for (std::size_t i = 0; i < els.size(); ++i) {
      const auto ab = els.at(i).as_numbers();
      if (ab.size() != 2) els.at(i).fail("[node1, node2]");
      const int a = static_cast<int>(ab[0]), b = static_cast<int>(ab[1]);
      if (a < 0 || b < 0 || a >= m.num_nodes() || b >= m.num_nodes() || a == b || ab[0] != a || ab[1] != b)
        els.at(i).fail("two different node indices in [0, " + std::to_string(m.num_nodes() - 1) + "]");
      if ((m.reference_position(a) - m.reference_position(b)).norm() <= 0)
        els.at(i).fail("an element of non-zero length");
      m.add_element(a, b, sec, up);
    }
  }
  return fixation_default;
}

// fixation w.r.t. the device axis: radial (only radial motion), axial (axial translation
// fixed), circumferential (circumferential translation fixed). Values: a node list, 'auto'
// (generator: 4 bottom crowns of the middle ring), 'rings' (4 bottom crowns of every ring).
void read_fixation(const Node& fx, BeamScene& bs, const std::vector<int>& fixation_default) {
  BeamModel& m = *bs.model;
  const int nn = m.num_nodes();
  std::vector<int> ring_fixation;
  if (bs.stent) ring_fixation = bs.stent->ring_fixation_nodes;
  fx.check_keys();
  for (const char* kind : {"radial", "axial", "circumferential"}) {
    if (!fx.has(kind)) continue;
    const Node r = fx.child(kind);
    std::vector<int> nodes;
    if (r.is_scalar() && (r.as_string() == "auto" || r.as_string() == "rings")) {
      if (!bs.generated_stent) r.fail("a list of node indices ('auto'/'rings' need the stent generator)");
      nodes = r.as_string() == "auto" ? fixation_default : ring_fixation;
    } else if (r.is_scalar() && r.as_string() == "none") {
    } else {
      nodes = node_list(fx, kind, nn);
    }
    try {
      for (int n : nodes) {
        if (std::string(kind) == "radial")
          m.fix_radial_only(n);
        else if (std::string(kind) == "axial")
          m.fix_axial(n);
        else
          m.fix_circumferential(n);
      }
    } catch (const std::invalid_argument& e) {
      r.fail(std::string("nodes off the device axis (") + e.what() + ")");
    }
  }
}

// stent.supports: Dirichlet conditions of beam nodes, optionally prescribed along a load curve
void read_supports(const Node& sup, const scene::LoadCurves& curves, BeamModel& m) {
  const int nn = m.num_nodes();
  for (std::size_t i = 0; i < sup.size(); ++i) {
    const Node s = sup.at(i);
    s.check_keys();
    const auto nodes = node_list(s, "nodes", nn);
    std::array<bool, 6> f{};
    const Node fix = s.child("fix", "'all' or a list of x, y, z, rx, ry, rz");
    if (fix.is_scalar()) {
      if (fix.as_string() != "all") fix.fail("'all' or a list of x, y, z, rx, ry, rz");
      f.fill(true);
    } else {
      static const char* names[6] = {"x", "y", "z", "rx", "ry", "rz"};
      for (std::size_t k = 0; k < fix.size(); ++k) {
        const std::string d = fix.at(k).as_string();
        int idx = -1;
        for (int q = 0; q < 6; ++q)
          if (d == names[q]) idx = q;
        if (idx < 0) fix.at(k).fail("one of x, y, z, rx, ry, rz");
        f[idx] = true;
      }
    }
    const Curve c = to_curve(scene::curve_ref(s, "curve", curves));
    for (int n : nodes) {
      m.fix(n, f);
      if (s.has("displacement")) {
        const Vec3 u = v3(s.get<std::array<double, 3>>("displacement"));
        for (int k = 0; k < 3; ++k)
          if (u(k) != 0.0) {
            if (!f[k]) s.child("displacement").fail("non-zero values only on fixed directions");
            m.prescribed_displacements.push_back({n, k, u(k), c});
          }
      }
      if (s.has("rotation")) {
        if (!(f[3] && f[4] && f[5])) s.child("rotation").fail("rx, ry and rz all fixed for a prescribed rotation");
        m.prescribed_rotations.push_back({n, v3(s.get<std::array<double, 3>>("rotation")), c});
      }
    }
  }
}

// stent.loads: nodal, line and radial line loads along load curves
void read_loads(const Node& loads, const scene::LoadCurves& curves, BeamModel& m) {
  const int nn = m.num_nodes(), ne = m.num_elements();
  for (std::size_t i = 0; i < loads.size(); ++i) {
    const Node l = loads.at(i);
    const std::string type = l.get<std::string>("type");
    const Curve c = to_curve(scene::curve_ref(l, "curve", curves));
    if (type == "nodal") {
      l.check_keys({"type", "nodes", "force", "moment", "curve"});
      Vec3 F = Vec3::Zero(), M = Vec3::Zero();
      if (l.has("force")) F = v3(l.get<std::array<double, 3>>("force"));
      if (l.has("moment")) M = v3(l.get<std::array<double, 3>>("moment"));
      for (int n : node_list(l, "nodes", nn)) m.nodal_loads.push_back({n, F, M, c});
    } else if (type == "line") {
      l.check_keys({"type", "elements", "q", "curve"});
      m.line_loads.push_back({element_list(l, "elements", ne), v3(l.get<std::array<double, 3>>("q")), c});
    } else {
      l.check_keys({"type", "elements", "magnitude", "curve", "follower"});
      m.radial_loads.push_back(
          {element_list(l, "elements", ne), l.get<double>("magnitude"), c, l.get<bool>("follower")});
    }
  }
}

}  // namespace

BeamScene load_beam_scene(const std::string& path) { return beam_scene_from(scene::load_scene(path)); }

BeamScene beam_scene_from(const Node& root) {
  BeamScene bs;
  bs.file = root.file();
  bs.time = scene::time_settings(root);
  bs.output = scene::output_settings(root);
  const scene::LoadCurves curves = scene::load_curves(root);
  const Node st = root.child("stent", "the beam model (generator or nodes/elements)");
  st.check_keys();
  bs.model = std::make_unique<BeamModel>();
  BeamModel& m = *bs.model;
  const int sec = m.add_section(read_section(st));

  // element: {residual: consistent | petrov_galerkin} (element.hpp, ResidualForm)
  if (auto el = st.optional("element")) {
    el->check_keys();
    if (el->get<std::string>("residual") == "petrov_galerkin") m.residual_form = ResidualForm::petrov_galerkin;
  }

  if (auto c = st.optional("contact")) {
    c->check_keys();
    m.sample_points_per_element = c->get<int>("points_per_element");
  }

  const std::vector<int> fixation_default = read_geometry(st, sec, bs);
  if (m.num_elements() == 0) st.fail("at least one element");

  if (auto ax = st.optional("axis")) {
    ax->check_keys();
    m.axis.points = read_points(ax->child("points", "a list of points [x, y, z]"));
  }

  if (auto fx = st.optional("fixation")) read_fixation(*fx, bs, fixation_default);
  if (auto sup = st.optional("supports")) read_supports(*sup, curves, m);
  if (auto loads = st.optional("loads")) read_loads(*loads, curves, m);

  if (auto so = st.optional("solver")) {
    so->check_keys();
    m.newton.linear_solver = so->get<std::string>("linear_solver");
    m.newton.max_iterations = so->get<int>("max_iterations");
    m.newton.residual_tol = so->get<double>("residual_tol");
    m.newton.residual_rel_tol = so->get<double>("residual_rel_tol");
    m.newton.increment_tol = so->get<double>("increment_tol");
    m.newton.line_search = so->get<bool>("line_search");
  }
  try {
    m.finalize();
  } catch (const std::invalid_argument& e) {
    st.fail(std::string("a consistent model (") + e.what() + ")");
  }
  if (auto is = st.optional("initial_state")) {  // continue from an earlier run's committed stent
    is->check_keys();
    const Node file = is->child("file", "the path of a beam state file (<run>/beam/state.h5 of an earlier run)");
    try {
      bs.initial_state = read_beam_state(scene::resolve_path(*is, file.as_string()));
      check_beam_state(*bs.initial_state, m);
    } catch (const std::runtime_error& e) {
      file.fail(std::string("a beam state file of this scene's stent: ") + e.what());
    }
    scene::require_start_at(root, bs.time, bs.initial_state->time, bs.initial_state->path);
  }
  return bs;
}

}  // namespace angio::beam
