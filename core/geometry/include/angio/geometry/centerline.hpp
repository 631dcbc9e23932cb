// Centerline of a curved device (stent, balloon, artery), shared by beam_solver and solid_solver.
//
// Paper §2.4: a curved stent (and balloon) is the straight device warped onto a centerline
// "in such a way that the stent centerline is not stretched" and "the rotational aspect of the
// transformation is chosen to minimize the twist". Here:
//  * the centerline is a polyline; its arc length s is the straight device's axial coordinate z
//    (no stretching along the axis);
//  * the cross-section frame {n1, n2} is transported with minimal twist: rotation-minimizing
//    frames at the vertices by the double reflection method (Wang, Jüttler, Zheng, Liu 2008,
//    ACM TOG 27(1) 2), interpolated between vertices by quaternion slerp;
//  * a straight-device point with cylindrical coordinates (θ, z, r) goes to
//    map(θ, s, r) = c(s) + r (cos θ n1(s) + sin θ n2(s)), s = z + (arc length where the device
//    starts).
// Units: mm (whatever the points are given in).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace angio::geometry {

using Vec3 = Eigen::Vector3d;

// Right-handed orthonormal frame: tangent along the centerline, normal2 = tangent × normal1.
struct Frame {
  Vec3 tangent = Vec3::UnitZ();
  Vec3 normal1 = Vec3::UnitX();
  Vec3 normal2 = Vec3::UnitY();
};

// Rotation-minimizing frames (double reflection) at the vertices of a polyline (>= 2 points,
// no repeated consecutive points). Vertex tangents are central differences (one-sided at the
// ends); the first normal is the global x axis (y if the first tangent is nearly along x)
// projected onto the first normal plane.
std::vector<Frame> rotation_minimizing_frames(const std::vector<Vec3>& pts);

class Centerline {
 public:
  // Throws std::invalid_argument for fewer than 2 points or repeated consecutive points.
  explicit Centerline(std::vector<Vec3> points);

  const std::vector<Vec3>& points() const { return pts_; }
  const std::vector<double>& arc_length() const { return s_; }  // cumulative, s[0] = 0
  double length() const { return s_.back(); }
  const std::vector<Frame>& frames() const { return F_; }  // RMF at the vertices

  // Point at arc length s: linear along the segments; beyond the ends extrapolated along the end
  // segments (so a device may stick out of the centerline a little).
  Vec3 point(double s) const;
  // Frame at arc length s: slerp between the vertex frames, constant beyond the ends.
  Frame frame(double s) const;
  // Straight-device cylindrical coordinates (θ, s = arc length, r) → 3D point.
  Vec3 map(double theta, double s, double r) const;
  // Unit radial direction cos θ n1(s) + sin θ n2(s).
  Vec3 radial(double theta, double s) const;

  // Closest point in the sense of the warp: the arc length s at which x lies in the normal plane
  // of frame(s), i.e. (x − point(s))·tangent(s) = 0, nearest such s if there are several. For a
  // warped point map(θ, s, r) this returns exactly s and distance r (up to round-off), which a
  // plain distance to the polyline does not (its kinks are off by O(r·Δφ²)).
  struct Closest {
    double s = 0;         // arc length (may be < 0 or > length() beyond the ends)
    double distance = 0;  // |x − point(s)|: radial distance from the curved axis
    Vec3 foot = Vec3::Zero();
    Frame frame;                 // frame(s)
    Vec3 radial = Vec3::Zero();  // (x − foot)/distance, zero on the axis
  };
  Closest closest(const Vec3& x) const;

 private:
  // Segment i and local parameter t (unclamped, outside [0, 1] beyond the ends) of arc length s.
  void locate(double s, int& i, double& t) const;
  double normal_offset(const Vec3& x, double s) const;  // (x − point(s))·tangent(s)

  std::vector<Vec3> pts_;
  std::vector<double> s_;
  std::vector<Frame> F_;
  std::vector<Eigen::Quaterniond> Q_;  // vertex frames as quaternions (for slerp)
};

// Reads centerline points from a text file: one "x y z" (or "x,y,z", "x;y;z", tab separated)
// per line, '#' starts a comment. Throws std::runtime_error("path[:line]: ...").
std::vector<Vec3> read_centerline_points(const std::string& path);
// The centerline of a text file (same format); also throws std::invalid_argument from the
// constructor (coincident points), with the path prepended.
Centerline read_centerline(const std::string& path);

}  // namespace angio::geometry
