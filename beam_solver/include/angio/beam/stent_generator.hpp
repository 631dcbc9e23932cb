// "Corrugated rings" stent generator (paper §2.2, docs/design.md §7.1) and warping onto a centerline.
//
// Geometry (straight stent, axis = z, rings start at z = 0):
//  * ring k (k = 0..rings−1) is a zigzag of 2·crowns struts around the crimped circumference;
//    crown j (j = 0..2·crowns−1) sits at angle θ_j = 2π j /(2·crowns) and at z = k·pitch
//    (bottom crown, j even) or z = k·pitch + strut_height (top crown, j odd). Struts run on the
//    cylinder surface (straight in the unrolled pattern): circumferential offset π D/(2·crowns)
//    = 0.2258 mm, axial height 1.5 mm → strut length sqrt(1.5² + 0.2258²) = 1.517 mm.
//  * with strut_height = ring pitch (paper), the top crowns of ring k lie in the plane of the
//    bottom crowns of ring k+1, half a crown period away. Each connector is a short
//    circumferential link (straight in the unrolled pattern, 0.2258 mm) from top crown j of
//    ring k to bottom crown j+1 of ring k+1. The `connectors` links of a gap are spread evenly
//    around the circumference (2 → 180° apart); consecutive gaps are shifted by half that spacing
//    (90°) so the connectors alternate.
//  * every strut and connector is split into elements_per_strut / elements_per_connector
//    elements with nodes on the cylinder: 4 rings → 4·16·3 + 3·2·3 = 210 elements.
//  * fixation nodes (radial motion only): 4 bottom crowns of the middle ring, 90° apart.
// A curved stent is the straight one warped onto a centerline polyline (paper §2.4): axial
// coordinate z = arc length along the centerline (no stretching of the centerline) and the
// cross-section frame transported with minimal twist (rotation-minimizing frame, double
// reflection method). The warp is angio::geometry::Centerline::map (core/geometry), the
// same map the solid_solver uses for a curved balloon, so stent and balloon share one axis.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "angio/beam/material.hpp"
#include "angio/geometry/centerline.hpp"
#include "angio/scene/keys_generated.hpp"

namespace angio::beam {

struct StentParameters {
  // the scene's stent.generator keys (core/scene/keys.yaml): meaning and defaults there
  int rings = scene::keys::defaults::stent_generator_rings;
  int crowns = scene::keys::defaults::stent_generator_crowns;  // per ring side (2·crowns struts per ring)
  double crimped_diameter = scene::keys::defaults::stent_generator_crimped_diameter;  // mm, node cylinder
  double strut_height = scene::keys::defaults::stent_generator_strut_height;          // mm, crown height
  double ring_pitch = scene::keys::defaults::stent_generator_ring_pitch;              // mm
  int connectors = scene::keys::defaults::stent_generator_connectors;  // per gap between neighbouring rings
  int elements_per_strut = scene::keys::defaults::stent_generator_elements_per_strut;
  int elements_per_connector = scene::keys::defaults::stent_generator_elements_per_connector;
  double start = scene::keys::defaults::stent_generator_start;  // mm of centerline arc length (−1: centred)
};

struct StentMesh {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 2>> elements;
  std::vector<Vec3> element_up;               // reference e2 direction (outward radial) per element
  std::vector<int> element_kind;              // 0 strut, 1 connector
  std::vector<int> element_group;             // strut or connector index (elements of one strut share it)
  std::vector<int> fixation_nodes;            // 4 bottom crowns of the middle ring, 90° apart
  std::vector<int> ring_fixation_nodes;       // 4 bottom crowns of every ring, 90° apart
  std::vector<int> distal_nodes;              // outer crowns of the end rings (dogboning)
  std::vector<int> central_nodes;             // crowns of the middle ring(s)
  std::vector<std::vector<int>> ring_crowns;  // crowns of each ring, rings in order (ring_axis.hpp)
  std::vector<Vec3> axis;                     // device axis polyline
  int num_struts = 0, num_connectors = 0;
};

// Straight stent along +z from z = 0 (centerline empty), or warped onto the centerline
// starting at arc length p.start (−1: centred). Throws std::invalid_argument on bad parameters,
// a centerline shorter than the stent, or a degenerate centerline.
StentMesh generate_corrugated_rings(const StentParameters& p, const std::vector<Vec3>& centerline = {});
StentMesh generate_corrugated_rings(const StentParameters& p, const geometry::Centerline& centerline);

}  // namespace angio::beam
