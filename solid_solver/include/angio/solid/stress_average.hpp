// A stress read at a physical length instead of at one element (pure function, no MPI). Units: mm, MPa.
//
// A strut modelled as a beam presses the wall along a line, and the stress of a line load on an
// elastic body grows as 1/r towards the line (Flamant; Johnson, Contact Mechanics, 1985, §2.2): the
// element maximum, and a 99th percentile whose 1 % of the volume lies within the strut's own radius,
// are set by the element size there and grow under refinement instead of converging. The
// mixed-dimensional model itself holds only for solid elements not smaller than the beam's cross
// section (Datz et al., §2.4, after Steinbrecher et al.), so refining towards the line is not an
// option either. Averaged over a ball of fixed radius ρ, the 1/r field is integrable and the average
// converges as h/ρ → 0 (the "volume method" of the theory of critical distances, Taylor, The Theory
// of Critical Distances, 2007, §2.5).
#pragma once
#include <cstddef>
#include <limits>
#include <vector>

#include "angio/solid/mesh.hpp"

namespace angio::solid {

// For every centre c: the weighted mean of `value` over the sample points within `radius` of c,
// Σ w_j f_j / Σ w_j over |x_j − c| ≤ radius (NaN where no point lies in the ball). The sample points
// discretize the integral over the ball: the Gauss points of one group's elements (one layer: stresses
// jump across layer interfaces and are averaged within a layer only) with their volumes; centres at
// the elements' centroids and the nodes, so that a ball also sits on the lumen, where a layer's stress
// peaks (with centroids alone the best ball's centre moves with the element size: 4 % between the
// generic artery's two finest meshes under blood pressure alone at 0.25 mm, against 0.9 % with the nodes and
// the Gauss points). Neighbours through the contact search's AABB tree (contact/search.hpp); cost
// O(centres · (log points + points per ball)). radius ≤ 0 or non-finite: invalid_argument.
std::vector<double> ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                                 const std::vector<double>& value, const std::vector<double>& weight, double radius);

// The maximum of ball_average over the centres and the first centre that attains it, without averaging
// every ball: a mean never exceeds its largest value, so only balls around the points with the largest
// values can hold the maximum (branch and bound; exact, the same value and centre as a scan of
// ball_average's field). `balls` counts the balls averaged. No centre or no point: value NaN, centre none.
struct BallMaximum {
  static constexpr std::size_t none = std::size_t(-1);
  double value = std::numeric_limits<double>::quiet_NaN();
  std::size_t centre = none;
  std::size_t balls = 0;
};
BallMaximum max_ball_average(const std::vector<Vec3d>& centre, const std::vector<Vec3d>& point,
                             const std::vector<double>& value, const std::vector<double>& weight, double radius);

}  // namespace angio::solid
