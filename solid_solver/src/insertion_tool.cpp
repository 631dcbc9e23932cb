#include "angio/solid/insertion_tool.hpp"

#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "angio/contact/capsule_tool.hpp"
#include "angio/solid/artery_measures.hpp"
#include "angio/solid/model.hpp"
#include "petsc_check.hpp"

namespace angio::solid {

InsertionTool::InsertionTool(const SolidModel& model, Options opt) : opt_(std::move(opt)) {
  const SurfaceSet* s = model.mesh().surface(opt_.surface);
  if (!s) throw std::runtime_error("insertion tool: no surface set '" + opt_.surface + "'");
  const std::vector<double> area = nodal_areas(model.mesh(), *s);  // by node (0 off the surface)
  for (int n = 0; n < int(area.size()); ++n) {
    const int k = model.new_index(n);
    if (area[n] > 0.0 && k >= model.owned_node_begin() && k < model.owned_node_end()) {
      nodes_.push_back(n);
      area_.push_back(area[n]);
    }
  }
}

void InsertionTool::add(const SolidModel& model, Vec r, Mat K) {
  const double R = opt_.radius(model.time());
  // sums: active nodes, force (3), |force|, energy; max penetration
  double sum[6] = {0, 0, 0, 0, 0, 0}, max_pen = 0.0;
  if (R > 0.0) {
    PetscInt idx[3];
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      const int n = nodes_[i];
      const contact::ToolNodeContact c =
          contact::capsule_node(contact::polyline_distance(opt_.axis, model.position(n)), R, opt_.penalty * area_[i]);
      if (!c.active) continue;
      for (int k = 0; k < 3; ++k) idx[k] = model.dof(n, k);
      ANGIO_PETSC(VecSetValues(r, 3, idx, c.r.data(), ADD_VALUES));
      if (K) ANGIO_PETSC(MatSetValues(K, 3, idx, 3, idx, c.K.data(), ADD_VALUES));  // symmetric
      sum[0] += 1.0;
      for (int k = 0; k < 3; ++k) sum[1 + k] -= c.r(k);
      sum[4] += c.r.norm();
      sum[5] += c.energy;
      max_pen = std::max(max_pen, c.penetration);
    }
  }
  double g[6], gmax = 0.0;
  MPI_Allreduce(sum, g, 6, MPI_DOUBLE, MPI_SUM, model.comm());
  MPI_Allreduce(&max_pen, &gmax, 1, MPI_DOUBLE, MPI_MAX, model.comm());
  last_ = ContactSummary{};
  last_.num_points = int(g[0]);
  last_.num_active = int(g[0]);
  last_.force = std::sqrt(g[1] * g[1] + g[2] * g[2] + g[3] * g[3]);
  last_.force_magnitude = g[4];
  last_.energy = g[5];
  last_.min_gap = -gmax;
}

}  // namespace angio::solid
