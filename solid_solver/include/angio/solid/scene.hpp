// Reading the solid parts of a scene (balloon:, artery:, solid:) into a mesh, materials, loads
// and solver options. See solid_solver/README.md for the keys.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "angio/scene/load_curve.hpp"
#include "angio/scene/node.hpp"
#include "angio/scene/output_settings.hpp"
#include "angio/solid/model.hpp"
#include "angio/solid/state_file.hpp"

namespace angio::solid {

struct PressureSpec {
  std::string surface;
  double value = 0.0;      // MPa, multiplied by the curve
  scene::LoadCurve curve;  // constant 1 when the scene gives none
  std::string label;       // "balloon_pressure" / "blood_pressure"
};
struct SpringSpec {
  std::string surface;
  double stiffness = 0.0;  // N/mm^3
};
// Balloon outer diameter stations for the summary (mid-length and both ends).
// Zero displacement of the given components on the nodes of a surface set.
struct FixedSpec {
  std::string surface;
  std::vector<int> components;
};
struct DiameterSpec {
  std::string node_set;  // outer surface nodes
  Axis axis;
  // Curved balloon (mesh.centerline): stations are arc lengths along the centerline
  // (Centerline::closest), not coordinates along the straight `axis`. The diameter at a station is
  // measured about the centroid of its ring of nodes (SolidRunner::balloon_diameters).
  std::optional<geometry::Centerline> centerline;
  double s_mid = 0.0, s_end0 = 0.0, s_end1 = 0.0;  // axial coordinates (arc lengths) along the axis
  double station(const Vec3d& X) const {
    return centerline ? centerline->closest(X).s : (X - axis.origin).dot(axis.direction);
  }
};

// solid.newton.atol must stay below this fraction of peak_load_norm (a scene error otherwise).
inline constexpr double kMaxAtolOfLoad = 0.1;
// Above this fraction the solver warns (see docs/validation.md "Error against run time", Newton-tolerance ladder).
inline constexpr double kWarnAtolOfLoad = 1e-3;

struct SolidScene {
  Mesh mesh;
  std::vector<LayerMaterial> materials;  // per mesh block
  ModelOptions options;
  std::vector<PressureSpec> pressures;
  std::vector<SpringSpec> springs;
  std::vector<FixedSpec> fixed;
  std::optional<DiameterSpec> balloon_diameter;
  // The balloon's axis from end to end as a polyline (mm; the centerline sampled every 0.25 mm for a
  // curved balloon): the spine of the insertion tool with `contact.insertion.axis: balloon`.
  std::vector<Vec3d> balloon_spine;
  // Artery summary (artery.summary): lumen stations along the vessel axis (artery_inner nodes) and the
  // apposition threshold (a strut farther than this from the endothelium is malapposed).
  std::optional<DiameterSpec> lumen;  // node_set: "artery_inner"
  int lumen_max_stations = scene::keys::defaults::artery_summary_lumen_stations;
  double apposition_threshold = scene::keys::defaults::artery_summary_apposition_threshold;    // mm
  double stress_average_radius = scene::keys::defaults::artery_summary_stress_average_radius;  // mm
  bool has_balloon = false, has_artery = false;
  int ranks = 0;  // solid.ranks (0: not given)
  // Norm of the nodal force vector of all pressures at their curves' peaks, reference mesh (N): the
  // scale solid.newton.atol is checked against (load_scale.hpp).
  double peak_load_norm = 0.0;
  scene::OutputSettings output;
  // solid.initial_state: the run continues from these parts of a state file (state_file.hpp), read
  // and checked against the mesh while the scene is read; time.start is the state's time.
  std::optional<StateFile> initial_state;
  std::vector<std::string> initial_parts;
  scene::TimeSettings time;
};

// Throws scene::SceneError ("file: key.path: expected ...") on invalid input.
SolidScene read_solid_scene(const scene::Node& root);

}  // namespace angio::solid
