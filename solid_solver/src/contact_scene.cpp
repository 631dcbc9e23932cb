#include "angio/solid/contact_scene.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "angio/common/log.hpp"

namespace angio::solid {

namespace {
using scene::Node;

// An entry is a map of options, or `off`/`false` to disable the pair.
bool disabled(const Node& n) {
  if (!n.is_scalar()) return false;
  const std::string v = n.as_string();
  if (v == "off" || v == "false") return true;
  n.fail("a map of options (e.g. {penalty: 10.0}) or 'off'");
}

std::optional<double> read_line_pair(const Node& c, const std::string& key, std::optional<double> def) {
  const auto n = c.optional(key);
  if (!n) return def;
  if (disabled(*n)) return std::nullopt;
  n->check_keys({"penalty"});
  return n->positive_or("penalty", def.value_or(contact::kLinePenaltyDefault));
}
}  // namespace

ContactSpec read_contact_spec(const Node& root) {
  ContactSpec spec;
  const auto c = root.optional("contact");
  if (!c) return spec;
  if (c->is_scalar() && disabled(*c)) {
    spec.stent_balloon.reset();
    spec.stent_artery.reset();
    spec.balloon_artery.reset();
    return spec;
  }
  c->check_keys({"stent_balloon", "stent_artery", "balloon_artery", "search_radius", "line_regularization", "line_normals",
                "log"});
  spec.search_radius = c->positive_or("search_radius", spec.search_radius);
  spec.line_regularization = c->non_negative_or("line_regularization", spec.line_regularization);
  if (!(spec.line_regularization < 0.5 * spec.search_radius))
    c->child("line_regularization").fail("a value below half of contact.search_radius (mm)");
  spec.line_averaged_normals = c->choice_or("line_normals", {"closest_point", "averaged"}, "closest_point") == "averaged";
  spec.log = c->boolean_or("log", spec.log);
  spec.stent_balloon = read_line_pair(*c, "stent_balloon", spec.stent_balloon);
  spec.stent_artery = read_line_pair(*c, "stent_artery", spec.stent_artery);
  if (const auto n = c->optional("balloon_artery")) {
    if (disabled(*n)) {
      spec.balloon_artery.reset();
    } else {
      n->check_keys({"penalty", "quadrature", "two_pass"});
      auto& o = *spec.balloon_artery;
      o.penalty = n->positive_or("penalty", o.penalty);
      o.quadrature = int(n->integer_or("quadrature", o.quadrature, 1));
      if (o.quadrature > 7) n->child("quadrature").fail("a quadrature degree between 1 and 7");
      o.two_pass = n->boolean_or("two_pass", o.two_pass);
    }
  }
  if (spec.balloon_artery) spec.balloon_artery->search_radius = spec.search_radius;
  return spec;
}

ContactSetup::ContactSetup(SolidRunner& runner, const ContactSpec& spec) : runner_(runner) {
  const SolidModel& model = runner.model();
  const Mesh& mesh = model.mesh();
  const bool has_balloon = mesh.surface("balloon_outer") != nullptr;
  const bool has_artery = mesh.surface("artery_inner") != nullptr;
  PenaltyStentContact::Options so;
  so.search_radius = spec.search_radius;
  so.regularization = spec.line_regularization;
  so.averaged_normals = spec.line_averaged_normals;
  if (has_balloon) so.balloon_penalty = spec.stent_balloon;
  if (has_artery) so.artery_penalty = spec.stent_artery;
  if (so.balloon_penalty || so.artery_penalty) {
    stent_ = std::make_unique<PenaltyStentContact>(model, so);
    composite_.set_stent(stent_.get());
  }
  if (spec.balloon_artery && has_balloon && has_artery) {
    balloon_artery_ = std::make_unique<PenaltySurfaceContact>(model, *spec.balloon_artery);
    composite_.add_model(balloon_artery_.get());
  }
  const bool log = spec.log;
  composite_.after_reply = [this, log](const SolidModel& m, const participant::ContactReply& reply) {
    if (!log || m.rank() != 0) return;
    // the solve's own split (SolveReport): contact add() inside its assemblies only
    const double dt_contact = runner_.last_report().contact_seconds;
    const double dt_solve = runner_.last_report().total_seconds;
    std::ostringstream os;
    os << std::setprecision(4) << "contact t=" << m.time();
    if (stent_ && stent_->num_points() > 0)
      os << " stent: " << reply.n_active << "/" << stent_->num_points() << " points active, min gap "
         << reply.min_gap << " mm, |sum w q| "
         << std::sqrt(reply.total_force[0] * reply.total_force[0] + reply.total_force[1] * reply.total_force[1] +
                      reply.total_force[2] * reply.total_force[2])
         << " N;";
    if (balloon_artery_) {
      const auto& s = balloon_artery_->last();
      os << " balloon-artery: " << s.num_active << "/" << s.num_points << " Gauss points active, min gap " << s.min_gap
         << " mm, sum|f| " << s.force_magnitude << " N, area " << balloon_artery_->active_area() << " mm^2;";
    }
    os << " contact time " << dt_contact << " s of " << dt_solve << " s solve";
    if (dt_solve > 0) os << " (" << std::setprecision(3) << 100.0 * dt_contact / dt_solve << " %)";
    LOG_INFO(os.str());
  };
  runner.set_stent_contact(&composite_);
  // forces on the endothelium per contact, in the runner's summary
  if (stent_) runner.add_contact_report("stent", stent_.get());
  if (balloon_artery_) runner.add_contact_report("balloon", balloon_artery_.get());
}

ContactSetup::~ContactSetup() {
  runner_.set_stent_contact(nullptr);
  runner_.clear_contact_reports();
}

std::unique_ptr<ContactSetup> make_contact(const Node& root, SolidRunner& runner) {
  return std::make_unique<ContactSetup>(runner, read_contact_spec(root));
}

}  // namespace angio::solid
