// Solid meshes: element blocks (one material each), surface sets (pressure, springs, contact),
// node sets; built-in tube generator and gmsh .msh 4.1 reader (ASCII and binary).
#pragma once
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "angio/geometry/centerline.hpp"
#include "angio/solid/elements.hpp"

namespace angio::solid {

struct Element {
  ElemType type = ElemType::Hex8;
  int block = 0;            // index into Mesh::blocks
  std::array<int, 10> n{};  // node indices (first num_nodes(type) used)
  int nn() const { return num_nodes(type); }
};

struct Face {
  FaceType type = FaceType::Quad4;
  std::array<int, 6> n{};
  int nn() const { return num_nodes(type); }
};

struct Block {
  std::string name;  // e.g. "balloon", "media", "adventitia"
  std::string part;  // "balloon" or "artery" (used for summaries)
};

struct SurfaceSet {
  std::string name;  // e.g. "balloon_inner", "artery_endo", "artery_end0"
  std::vector<Face> faces;
};

// Straight axis used to build local frames (circumferential/axial/radial) per element.
struct Axis {
  Vec3d origin = Vec3d::Zero();
  Vec3d direction = Vec3d::UnitZ();
};

struct Mesh {
  std::vector<Vec3d> X;
  std::vector<Element> elements;
  std::vector<Block> blocks;
  std::vector<SurfaceSet> surfaces;
  std::map<std::string, std::vector<int>> node_sets;
  // Optional local material frame per element (fiber directions); empty: built from the model's axis.
  std::vector<Frame> frames;

  int block_index(const std::string& name) const;  // -1 if absent
  const SurfaceSet* surface(const std::string& name) const;
  // Append another mesh (node/element indices shifted, names kept).
  void append(const Mesh& other);
  // Orient every surface face so that its normal points out of the adjacent volume element.
  // Throws if a face has no adjacent element.
  void orient_surfaces();
};

// Structured hex8 tube: layers from inside to outside; blocks named after the layers,
// surfaces <prefix>inner, <prefix>outer, <prefix>end0 (z = z0), <prefix>end1 (z = z0 + length).
// Axis along +z through `center`, the tube spans z in [center.z - L/2, center.z + L/2].
// Curved tube (paper §2.4, §3.2): with a centerline the straight tube's node (θ, z, r) goes to
// centerline.map(θ, start + z, r), z in [0, length] (the axis is not stretched, the cross-section
// frame has minimal twist: the same warp as the stent's); `center` is not used. Fiber frames
// then follow the curved axis (set_frames_from_curved_axis).
// Resolution where the stresses are read: `progression` grades a layer's elements radially (each
// this many times thicker than the one inside it, gmsh's "Progression"; > 1: finest at the lumen,
// where the struts press), TubeAxialRefinement shortens the elements over an axial window (the
// stented segment). Both keep the mesh structured and conforming.
struct TubeLayer {
  std::string name;
  double thickness = 0.0;
  int n_radial = 1;
  double progression = 1.0;
};
// Elements `factor` times shorter than length/n_axial over the window [from, to] (mm along the axis
// from the tube's centre); the parts outside keep about length/n_axial (counts rounded, at least one
// element per non-empty part). factor 1: uniform.
struct TubeAxialRefinement {
  double from = 0.0, to = 0.0;  // mm, from the tube's centre
  double factor = 1.0;
  // Axial node stations from end0 (mm), n + 1 of them for n elements, from 0 to length.
  std::vector<double> stations(double length, int n_axial) const;
};
// Idealized concentric stenosis of a tube (the straight stenosed vessel of the stenting literature,
// e.g. Lally et al., J Biomech 38 (2005) 1574; Zahedmanesh & Lally, Med Biol Eng Comput 47 (2009)
// 385): the lumen radius narrows as a cosine bump,
//     r(z) = R_i (1 − s (1 + cos(2π (z − z_s)/L))/2)   for |z − z_s| ≤ L/2,   R_i elsewhere,
// s the diameter stenosis (1 − D_min/D_ref), z_s its centre (axial, from the tube's centre), L its
// length. The innermost layer takes up the narrowing (it is the plaque or intima): its shells are
// spread evenly between r(z) and its outer radius, the other layers keep their thickness.
struct TubeStenosis {
  double severity = 0.0;  // 0 = none, < 1
  double length = 0.0;    // mm
  double position = 0.0;  // mm, centre along the axis from the tube's centre
  // lumen radius at axial coordinate z (from the tube's centre) of a tube with inner radius Ri
  double lumen_radius(double Ri, double z) const;
};
struct TubeSpec {
  std::string part;            // "balloon" / "artery"
  std::string surface_prefix;  // e.g. "balloon_"
  double length = 1.0;
  double inner_radius = 1.0;
  std::vector<TubeLayer> layers;
  int n_circ = 16;
  int n_axial = 8;
  Vec3d center = Vec3d::Zero();
  std::optional<geometry::Centerline> centerline;  // curved axis (none: straight along +z)
  double start = 0.0;                              // mm, arc length of end0 on the centerline
  TubeStenosis stenosis;
  TubeAxialRefinement axial_refinement;
};
// Throws std::runtime_error on bad parameters or a tube that does not fit on the centerline.
Mesh make_tube(const TubeSpec& spec);

// gmsh .msh 4.1, ASCII or binary (data-size 8, this machine's byte order). Volume physical groups become
// blocks (name = physical name, or "volume_<entity tag>" for a volume without one), surface
// physical groups become surface sets (<surface_prefix><name>, or "surface_<tag>"). Supported
// element types: hex8 (5), tet4 (4), tet10 (11), quad4 (3), tri3 (2), tri6 (9); other known gmsh
// types are skipped. Unknown sections are skipped; MSH 2.x/4.0 and partitioned meshes are refused.
// Coordinates are multiplied by `scale`. Every count is checked against the bytes left in the file
// before anything is allocated. Throws std::runtime_error("file:line: ..." for ASCII,
// "file: ... at byte offset N" for binary files) on bad input.
Mesh read_gmsh(const std::string& path, const std::string& part, const std::string& surface_prefix, double scale = 1.0);

// Local frame of an element from a straight axis (element centroid, reference geometry).
Frame element_frame(const Mesh& m, int e, const Axis& axis);
// Fill m.frames for every element from a straight axis.
void set_frames_from_axis(Mesh& m, const Axis& axis);
// Fill m.frames from a polyline centerline (>= 2 points): axial = tangent of the closest segment,
// radial = centroid minus its closest point (without the axial part), circumferential = axial x radial.
void set_frames_from_centerline(Mesh& m, const std::vector<Vec3d>& centerline);
// Fill m.frames w.r.t. a curved device axis (warped tubes): at the element centroid c,
// axial = tangent of centerline.frame(s) at s = centerline.closest(c).s, radial = c minus its
// foot (normal to the tangent), circumferential = axial x radial (right-handed, orthonormal).
void set_frames_from_curved_axis(Mesh& m, const geometry::Centerline& centerline);
Vec3d element_centroid(const Mesh& m, int e);
// The first element whose reference Jacobian determinant is not positive at a Gauss point or at one
// of its nodes (inverted, degenerate or folded), described with its index, type, block and
// centroid; empty when every element is valid.
std::string first_invalid_element(const Mesh& m);
// "a, b, c": the names of the mesh's blocks or surface sets (the latter without `prefix`), for
// messages that name what a mesh does have.
std::string block_names(const Mesh& m);
// The mesh's parts (Block::part), in the order of their first block.
std::vector<std::string> part_names(const Mesh& m);
std::string surface_names(const Mesh& m, const std::string& prefix);

}  // namespace angio::solid
