// Contact in the solid solver: the contact kernels of solid_solver/contact wired into
// SolidModel's ContactModel hook.
//
//  * PenaltyStentContact: stent (beam sample points, docs/design.md §5.1) against the balloon outer surface and/or
//    the artery endothelium, line-to-surface penalty (paper §2.5). A point may touch both surfaces; the line
//    loads add up. The beam points are held fixed during the solid's Newton solve (Dirichlet–Neumann).
//  * PenaltySurfaceContact: balloon outer surface (slave) against the artery endothelium (master),
//    Gauss-point-to-segment penalty (the paper uses mortar).
//  * CompositeContact: the StentContact registered with SolidRunner (SolidModel holds one ContactModel
//    pointer); forwards add() to both and the reply to the stent part.
//
// MPI: every rank holds the displacement of the surfaces' nodes (held_nodes), so every rank builds the searches
// over the WHOLE surfaces (no artificial free edges at partition boundaries) and evaluates a contiguous slice
// of the beam points / of the slave faces (two_pass: rank 0 evaluates everything); each rank adds its own
// contributions (ADD_VALUES, communicated by the model's assembly), so every contribution enters the global
// system exactly once.
// add() is collective (Allreduce of the diagnostics); fill_reply() and gaps() evaluate each rank's slice of
// the points (fill_reply: the last add()'s evaluation when it saw the same configuration) and gather them on
// rank 0, which answers the coupler.
// Units: mm, N, MPa.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "angio/contact/contact.hpp"
#include "angio/solid/participant.hpp"

namespace angio::solid {

// contact::Surface from a mesh surface set (faces oriented out of their volume: normal_sign = +1 makes the
// contact normal point out of the body, i.e. toward the stent / into the lumen).
contact::Surface to_contact_surface(const SurfaceSet& s, double normal_sign = 1.0);

// Summary of one contact evaluation (same on every rank after add()).
struct ContactSummary {
  int num_points = 0;    // (point or Gauss point, surface) pairs with a closest point in range
  int num_active = 0;    // pairs with g < 0
  double min_gap = 0.0;  // smallest gap (mm); +search radius if nothing was in range
  double force = 0.0;    // |net force| on the solid (line contact: on balloon+artery; surface: on the master), N
  double force_magnitude = 0.0;  // sum over pairs of |force| (N)
  double energy = 0.0;           // penalty potential (N mm)
};

// Wall time spent in add() (search update + evaluation + insertion into r/K), rank 0.
struct ContactTiming {
  long calls = 0;
  double seconds = 0.0;
  void reset() { *this = {}; }
};

// contact.line_tangent's value (keys.yaml) as LineContactParams::ring_tangent, ::force_tangent and
// ::definite_force_terms: the one reading of the key, for its default and for a scene (read_contact_spec).
struct LineTangentFlags {
  bool ring, force, definite;
};
constexpr LineTangentFlags line_tangent_flags(std::string_view value) {
  return {value == "ring", value != "gap", value == "definite"};
}
inline constexpr LineTangentFlags kLineTangentDefault = line_tangent_flags(scene::keys::defaults::contact_line_tangent);
inline constexpr bool kLineRingTangentDefault = kLineTangentDefault.ring;
inline constexpr bool kLineForceTangentDefault = kLineTangentDefault.force;
inline constexpr bool kLineDefiniteForceTermsDefault = kLineTangentDefault.definite;

// A contact pair that is on at every time (the default of `from`).
inline constexpr double kAlwaysActive = -std::numeric_limits<double>::infinity();

class PenaltyStentContact : public StentContact {
 public:
  struct Options {
    std::optional<double> balloon_penalty;                                // N/mm^2; unset: no stent-balloon contact
    std::optional<double> artery_penalty;                                 // N/mm^2; unset: no stent-artery contact
    double search_radius = scene::keys::defaults::contact_search_radius;  // mm; > R + the largest penetration
    double regularization = 0.0;                    // g0 (mm) of the linear-quadratic law (line_contact.hpp)
    bool averaged_normals = false;                  // projection along the averaged normal field (line_contact.hpp)
    bool ring_tangent = kLineRingTangentDefault;    // LineContactParams::ring_tangent (averaged normals only)
    bool force_tangent = kLineForceTangentDefault;  // LineContactParams::force_tangent
    bool definite_force_terms = kLineDefiniteForceTermsDefault;  // LineContactParams::definite_force_terms
    std::string balloon_surface = "balloon_outer";
    std::string artery_surface = "artery_inner";
    double balloon_from = kAlwaysActive, artery_from = kAlwaysActive;  // s: off before these times
  };
  // Surfaces that the mesh does not have are skipped (e.g. no artery in a free expansion scene).
  PenaltyStentContact(const SolidModel& model, Options opt);
  ~PenaltyStentContact() override;

  void set_points(const participant::SamplePoints& points) override;
  void add(const SolidModel& model, Vec r, Mat K) override;
  // With averaged normals a point's tangent couples its face's nodes with the rings of their normals
  // (the nodes of the faces around each); without, it stays within the face (an element's pattern).
  std::vector<NodeCoupling> couplings(const SolidModel& model) const override;
  std::vector<int> held_nodes(const SolidModel&) const override { return nodes_; }  // its surfaces'
  void load_levels(double t, std::vector<double>& out) const override;              // 1 or 0 per surface: on at t
  void fill_reply(const SolidModel& model, participant::ContactReply& reply) override;
  void gaps(const SolidModel& model, const std::string& surface, std::vector<double>& gap,
            std::vector<double>& weight) override;

  int num_surfaces() const { return int(surfaces_.size()); }
  const std::vector<std::string>& surface_names() const { return names_; }
  const ContactSummary& last() const { return last_; }  // of the last add()
  ContactTiming& timing() { return timing_; }
  std::size_t num_points() const { return points_.size(); }

 private:
  // Updates the searches to the current configuration and evaluates `points` against each surface (own penalty).
  // all = false: the surfaces that are off at the model's time are left out (add); true: they are
  // evaluated with penalty 0 so that the results stay indexed by surface (reply, gaps).
  // first: the index of points[0] in points_ (for the projection hints).
  std::vector<contact::LineContactResult> evaluate_(const SolidModel& model, std::span<const contact::BeamPoint> points,
                                                    std::size_t first, bool tangent, bool all);

  Options opt_;
  std::vector<std::string> names_;
  std::vector<double> penalty_;
  std::vector<double> from_;  // per surface: off before this time
  bool on_(std::size_t k, const SolidModel& model) const;
  std::vector<std::unique_ptr<contact::Surface>> surfaces_;
  std::vector<std::unique_ptr<contact::SurfaceSearch>> searches_;
  std::vector<contact::BeamPoint> points_;
  // Per surface and point: where the point projected at the last evaluation (a start for the next).
  // The points move little between the evaluations of a solve and between coupling iterations.
  std::vector<std::vector<contact::ProjectionHint>> hints_;
  // Per surface: its search tree was built for the current points' solve; later evaluations refit it
  // (same result; the tree's shape only decides how fast it answers).
  std::vector<char> built_;
  // Its surfaces' faces are numbered by contact node: node i is mesh node nodes_[i] (ascending), the
  // positions it reads; coordinate arrays, nodal normals and searches hold these nodes only.
  std::vector<int> nodes_;
  std::vector<contact::Vec3> coords_;  // by contact node
  // The last add()'s evaluation of this rank's slice when it covered every surface (every pair on), and
  // the coordinates it saw: fill_reply() at the same configuration (a converged Newton's last residual)
  // takes it instead of evaluating again. Dropped by set_points().
  std::vector<contact::LineContactResult> last_eval_;
  std::vector<contact::Vec3> last_eval_coords_;
  ContactSummary last_;
  ContactTiming timing_;
};

class PenaltySurfaceContact : public ContactModel {
 public:
  struct Options {
    // the scene's contact.balloon_artery keys (core/scene/keys.yaml): meaning and defaults there
    double penalty = scene::keys::defaults::contact_balloon_artery_penalty;     // N/mm^3 (pressure per penetration)
    int quadrature = scene::keys::defaults::contact_balloon_artery_quadrature;  // slave face rule degree
    double regularization = scene::keys::defaults::contact_balloon_artery_regularization;  // mm: C1 law below
    bool two_pass = scene::keys::defaults::contact_balloon_artery_two_pass;
    double search_radius = scene::keys::defaults::contact_search_radius;
    std::string slave = "balloon_outer";
    std::string master = "artery_inner";
    double from = kAlwaysActive;  // s: off before this time
  };
  // Throws std::runtime_error if a surface set is missing.
  PenaltySurfaceContact(const SolidModel& model, Options opt);
  ~PenaltySurfaceContact() override;
  // Evaluates the pairs of the current configuration (kept for add()) and returns the couplings of the
  // face pairs within the search radius that no earlier call returned.
  std::vector<NodeCoupling> prepare(const SolidModel& model, bool tangent) override;
  void add(const SolidModel& model, Vec r, Mat K) override;
  void load_levels(double t, std::vector<double>& out) const override { out.push_back(t >= opt_.from); }  // on at t
  std::vector<int> held_nodes(const SolidModel&) const override { return nodes_; }                        // its faces'

  const ContactSummary& last() const { return last_; }
  double active_area() const { return active_area_; }
  ContactTiming& timing() { return timing_; }

 private:
  Options opt_;
  std::unique_ptr<contact::Surface> slave_, master_;
  std::unique_ptr<contact::SurfaceSearch> ss_, sm_;
  // Collective: contact at the current configuration into evaluated_ (this rank's pairs) and last_.
  void evaluate_(const SolidModel& model, bool tangent);
  // of the master's faces and of the slave's this rank evaluates, ascending: contact node i (the faces'
  // numbering) is mesh node nodes_[i]
  std::vector<int> nodes_;
  std::vector<contact::Vec3> coords_;  // by contact node
  contact::SurfaceContactResult evaluated_;
  bool evaluated_tangent_ = false;
  bool prepared_ = false;                     // evaluated_ is prepare()'s, for the add() that follows it
  std::unordered_set<std::uint64_t> paired_;  // (pass, slave face, master face) returned by prepare()
  ContactSummary last_;
  double active_area_ = 0.0;
  ContactTiming timing_;
};

// The one contact registered with the runner: stent line contact (optional) + any other contact models.
class CompositeContact : public StentContact {
 public:
  void set_stent(PenaltyStentContact* s) { stent_ = s; }
  void add_model(ContactModel* m) { others_.push_back(m); }
  void set_points(const participant::SamplePoints& points) override;
  void add(const SolidModel& model, Vec r, Mat K) override;
  std::vector<NodeCoupling> couplings(const SolidModel& model) const override;        // of all its models
  std::vector<int> held_nodes(const SolidModel& model) const override;                // of all its models
  std::vector<NodeCoupling> prepare(const SolidModel& model, bool tangent) override;  // of all its models
  void load_levels(double t, std::vector<double>& out) const override;                // of all its models
  bool extrapolates(double from, double to) const override;                           // all its models
  void fill_reply(const SolidModel& model, participant::ContactReply& reply) override;
  void gaps(const SolidModel& model, const std::string& surface, std::vector<double>& gap,
            std::vector<double>& weight) override;
  StentContact* line_part() override { return stent_; }
  // Called on every rank after each converged solve's reply (e.g. logging of the contact diagnostics).
  std::function<void(const SolidModel&, const participant::ContactReply&)> after_reply;

 private:
  PenaltyStentContact* stent_ = nullptr;
  std::vector<ContactModel*> others_;
};

}  // namespace angio::solid
