// Virtual insertion: a rigid capsule of radius R(t) around the device axis (capsule_tool.hpp) pushes
// the lumen surface out of itself, so that a device wider than the lesion can be placed without
// starting inside the wall. The scene grows R from inside the narrowest lumen to the device's outer
// radius plus a clearance while the stent's and balloon's contact with the artery is still off
// (contact.<pair>.from), then shrinks it to 0 so that the wall comes to rest on the device.
//
//   contact:
//     insertion:
//       axis: [[0, 0, 0], [0, 0, 6]]          # mm, polyline (>= 2 points); the capsule's spine,
//                                             # or `balloon`: the balloon's axis from end to end
//       radius: {value: 0.7, curve: tool}     # mm × load curve (or a number: constant)
//       penalty: 100.0                        # N/mm^3: pressure per mm of penetration
//       surface: artery_inner                 # the surface it pushes (default)
//
// Each rank evaluates the surface nodes it owns (reference lumped nodal areas), so every node
// enters the global system once. Units: mm, N, MPa, s.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "angio/solid/stent_contact.hpp"

namespace angio::solid {

class InsertionTool : public ContactModel {
 public:
  struct Options {
    std::vector<Vec3d> axis;
    std::function<double(double)> radius;  // R(t), mm
    double penalty = 100.0;                // N/mm^3
    std::string surface = "artery_inner";
  };
  // Throws std::runtime_error if the surface set is missing.
  InsertionTool(const SolidModel& model, Options opt);
  void add(const SolidModel& model, Vec r, Mat K) override;  // collective (diagnostics)
  void load_levels(double t, std::vector<double>& out) const override { out.push_back(opt_.radius(t)); }
  // Not while the tool is in the lumen (radius > 0 at either end of the step). Measured on the CI
  // test's tight lesion (0.5 mm tet10): the solves of the tool's opening took 9-25 Newton iterations
  // from the extrapolated state against 4-9 from the committed one, full steps alternating with
  // line-search steps of 1/64. Likely cause, not examined further: the node-wise penalty's stiffness
  // switches as a node crosses the moving tool's surface, and the extrapolated state puts the wall's
  // nodes near it.
  bool extrapolates(double from, double to) const override {
    return opt_.radius(from) <= 0.0 && opt_.radius(to) <= 0.0;
  }

  const ContactSummary& last() const { return last_; }  // min_gap: −(largest penetration) (mm)
  double radius(double t) const { return opt_.radius(t); }

 private:
  Options opt_;
  std::vector<int> nodes_;    // surface nodes owned by this rank (original numbering)
  std::vector<double> area_;  // their lumped reference areas (mm^2)
  ContactSummary last_;
};

}  // namespace angio::solid
