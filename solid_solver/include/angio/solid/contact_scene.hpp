// The scene's top-level `contact:` section and the contact objects of a SolidRunner.
//
//   contact:
//     stent_balloon: {penalty: 10.0}               # N/mm^2, line-to-surface (paper §2.5); or `off`
//     stent_artery: {penalty: 10.0}                # N/mm^2; or `off`
//     line_regularization: 0.0                     # g0 (mm): 0 = linear penalty law (paper Eq. 4),
//                                                  # > 0 = C¹ linear-quadratic law (line_contact.hpp)
//     line_normals: closest_point                  # or averaged: projection along the averaged nodal
//                                                  # normal field (continuous normal; normal_field.hpp)
//     balloon_artery: {penalty: 5.0, quadrature: 3, two_pass: false}   # N/mm^3 (README of solid_contact); or `off`
//     search_radius: 0.3                           # mm (> beam radius + largest penetration)
//     insertion: {axis: [[x,y,z], ...], radius: {value: 0.7, curve: c}, penalty: 100.0}   # virtual
//                                                  # insertion tool (insertion_tool.hpp); absent: none
//   any pair: from: t                              # s: the pair is off before pseudo-time t (a device
//                                                  # placed inside the wall waits for the insertion tool)
//     log: true                                    # one line per converged solid solve (rank 0)
//
// Defaults (section or entry absent): the paper's values for the contact pairs whose surfaces exist
// (stent-balloon / stent-artery 10 N/mm^2, balloon-artery 5 when both balloon and artery are meshed).
#pragma once
#include <memory>
#include <optional>
#include <string_view>

#include "angio/scene/load_curve.hpp"
#include "angio/scene/node.hpp"
#include "angio/solid/insertion_tool.hpp"
#include "angio/solid/stent_contact.hpp"

namespace angio::solid {

struct ContactSpec {
  std::optional<double> stent_balloon = contact::kLinePenaltyDefault;  // N/mm^2, unset: off
  std::optional<double> stent_artery = contact::kLinePenaltyDefault;
  std::optional<PenaltySurfaceContact::Options> balloon_artery = PenaltySurfaceContact::Options{};
  double stent_balloon_from = kAlwaysActive, stent_artery_from = kAlwaysActive;  // s
  struct Insertion {
    std::vector<Vec3d> axis;                                            // mm
    bool balloon_axis = false;                                          // axis: balloon (SolidScene::balloon_spine)
    scene::ScaledCurve radius;                                          // mm
    double penalty = scene::keys::defaults::contact_insertion_penalty;  // N/mm^3
  };
  std::optional<Insertion> insertion;
  double search_radius = scene::keys::defaults::contact_search_radius;  // mm
  // g0, mm (line_contact.hpp LineContactParams::regularization)
  double line_regularization = scene::keys::defaults::contact_line_regularization;
  bool line_averaged_normals =  // LineContactParams::averaged_normals
      std::string_view(scene::keys::defaults::contact_line_normals) == "averaged";
  bool line_ring_tangent = kLineRingTangentDefault;                 // LineContactParams::ring_tangent
  bool line_force_tangent = kLineForceTangentDefault;               // LineContactParams::force_tangent
  bool line_definite_force_terms = kLineDefiniteForceTermsDefault;  // LineContactParams::definite_force_terms
  bool log = scene::keys::defaults::contact_log;
};

// Throws scene::SceneError ("file: contact.key: expected ...").
ContactSpec read_contact_spec(const scene::Node& root);

// Owns the contact models of one runner; registered with runner.set_stent_contact() on construction and
// unregistered on destruction (keep it alive as long as the runner solves).
class ContactSetup {
 public:
  ContactSetup(SolidRunner& runner, const ContactSpec& spec);
  ~ContactSetup();
  ContactSetup(const ContactSetup&) = delete;
  ContactSetup& operator=(const ContactSetup&) = delete;

  PenaltyStentContact* stent() { return stent_.get(); }
  PenaltySurfaceContact* balloon_artery() { return balloon_artery_.get(); }
  CompositeContact& composite() { return composite_; }

 private:
  SolidRunner& runner_;
  std::unique_ptr<PenaltyStentContact> stent_;
  std::unique_ptr<PenaltySurfaceContact> balloon_artery_;
  std::unique_ptr<InsertionTool> insertion_;
  CompositeContact composite_;
};

// Reads the `contact:` section and builds/registers the contact of a runner. Collective (all ranks).
std::unique_ptr<ContactSetup> make_contact(const scene::Node& root, SolidRunner& runner);

}  // namespace angio::solid
