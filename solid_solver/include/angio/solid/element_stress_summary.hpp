// Per block (layer) and step: the element stress's maximum, 99th percentile and ball-averaged maximum
// (stress_average.hpp), each rank working on its own elements. Units: mm, MPa.
#pragma once
#include <mpi.h>

#include <limits>
#include <vector>

#include "angio/solid/mesh.hpp"

namespace angio::solid {

class SolidModel;

struct ElementStressSummary {
  double max = -std::numeric_limits<double>::infinity();  // max over the block's elements (-inf: none)
  Vec3d where = Vec3d::Zero();                            // current centroid of that element
  // 99th percentile by reference volume (MPa), robust against one element at a strut
  double p99 = 0.0;
  // max of the element stress averaged over a ball of the scene's stress_average_radius: the measure
  // that converges under refinement at a strut (stress_average.hpp); NaN: none
  double max_averaged = std::numeric_limits<double>::quiet_NaN();
  Vec3d where_averaged = Vec3d::Zero();  // the centre of that ball (an element's centroid or a node, current)
};

// For every block of the model's mesh, from p1 and vol (per local element, the model's local_elements()
// order: first principal stress and reference volume). Result on rank 0; the other ranks get defaults.
// Collective.
//
// Each rank averages over the balls centred on its own elements' centroids and nodes, with its own
// elements' Gauss points and those of other ranks' elements that lie in a cell (at least the ball's
// radius wide) next to one of its centres: every point within the radius of them. Gathering the blocks' Gauss
// points on rank 0 instead held 67 MB there for the 0.25 mm patient artery (heaptrack, 8 ranks;
// docs/performance.md "What a rank holds at 8 ranks"). Ties between centres go to the element, then the
// node, of the lowest index, whatever the partition. The percentile gathers (block, value, volume) per
// element on rank 0 (24 bytes each). radius not positive and finite, or p1 / vol not one per local
// element: invalid_argument, on every rank alike.
std::vector<ElementStressSummary> element_stress_summary(MPI_Comm comm, const SolidModel& model,
                                                         const std::vector<double>& p1, const std::vector<double>& vol,
                                                         double radius);

}  // namespace angio::solid
