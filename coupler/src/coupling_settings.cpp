#include "angio/coupler/coupling_settings.hpp"

#include "angio/coupler/aitken.hpp"

#include <nlohmann/json.hpp>

namespace angio::coupler {

CouplingSettings coupling_settings(const scene::Node& root) {
  CouplingSettings s;
  for (const char* part : {"stent", "solid"})
    if (auto p = root.optional(part); p && p->is_map() && p->has("initial_state")) s.synchronize = true;
  auto c = root.optional("coupling");
  if (!c) return s;
  c->check_keys({"scheme", "acceleration", "initial_relaxation", "max_relaxation", "max_iterations", "rel_tol",
                 "abs_tol", "strict", "restart_growth", "prediction", "record", "iqn", "inexact_solid"});
  s.scheme = c->choice_or("scheme", {"dirichlet-neumann", "robin"}, s.scheme);
  s.acceleration = c->choice_or("acceleration", {"aitken", "iqn-ils", "constant"}, s.acceleration);
  if (c->has("initial_relaxation")) s.initial_relaxation = c->in_range("initial_relaxation", 1e-6, 2.0);
  s.max_relaxation =
      c->has("max_relaxation") ? c->in_range("max_relaxation", 1e-6, 10.0) : std::max(1.0, s.initial_relaxation);
  if (s.max_relaxation < s.initial_relaxation)
    c->child("max_relaxation").fail("a value >= coupling.initial_relaxation");
  if (auto iqn = c->optional("iqn")) {
    if (s.acceleration != "iqn-ils") iqn->fail("no iqn section (it applies only with coupling.acceleration: iqn-ils)");
    iqn->check_keys({"reused_steps", "max_columns", "filter", "stagnation"});
    s.iqn.reused_steps = static_cast<int>(iqn->integer_or("reused_steps", s.iqn.reused_steps, 0));
    s.iqn.max_columns = static_cast<int>(iqn->integer_or("max_columns", s.iqn.max_columns, 1));
    if (iqn->has("filter")) s.iqn.filter = iqn->in_range("filter", 1e-14, 0.99);
    if (iqn->has("stagnation")) s.iqn.stagnation = iqn->in_range("stagnation", 0.0, 0.99);
  }
  s.iqn.initial_relaxation = s.initial_relaxation;
  s.max_iterations = static_cast<int>(c->integer_or("max_iterations", s.max_iterations, 1));
  s.rel_tol = c->non_negative_or("rel_tol", s.rel_tol);
  s.abs_tol = c->non_negative_or("abs_tol", s.abs_tol);
  // rel_tol 1 accepts a residual as large as the contact loads themselves: every first iteration
  // passes and the coupling does nothing (the solid's atol has the like check against its loads)
  if (!(s.rel_tol < 1.0)) c->child("rel_tol").fail("a relative tolerance below 1 (typically 1e-3)");
  if (s.rel_tol == 0.0 && s.abs_tol == 0.0)
    c->fail("a positive coupling.rel_tol or coupling.abs_tol (both are 0: nothing can converge)");
  s.strict = c->boolean_or("strict", s.strict);
  if (c->has("restart_growth")) {
    s.restart_growth = c->non_negative_or("restart_growth", 0.0);
    if (s.restart_growth != 0.0 && !(s.restart_growth > 1.0))
      c->child("restart_growth").fail("0 (never restart) or a factor > 1");
  }
  s.prediction = c->choice_or("prediction", {"constant", "extrapolate"}, s.prediction);
  s.record = c->boolean_or("record", s.record);
  if (c->has("inexact_solid")) s.inexact_solid = c->in_range("inexact_solid", 0.0, 1.0);
  return s;
}

std::string settings_json(const CouplingSettings& s) {
  nlohmann::ordered_json j = {{"scheme", s.scheme},
                              {"acceleration", s.acceleration},
                              {"initial_relaxation", s.initial_relaxation},
                              {"max_relaxation", s.max_relaxation},
                              {"max_iterations", s.max_iterations},
                              {"rel_tol", s.rel_tol},
                              {"abs_tol", s.abs_tol},
                              {"strict", s.strict},
                              {"restart_growth", s.restart_growth},
                              {"prediction", s.prediction},
                              {"record", s.record},
                              {"inexact_solid", s.inexact_solid}};
  if (s.acceleration == "iqn-ils")
    j["iqn"] = {{"reused_steps", s.iqn.reused_steps},
                {"max_columns", s.iqn.max_columns},
                {"filter", s.iqn.filter},
                {"stagnation", s.iqn.stagnation}};
  return j.dump();
}

std::unique_ptr<Acceleration> make_acceleration(const CouplingSettings& s) {
  if (s.acceleration == "constant") return std::make_unique<ConstantRelaxation>(s.initial_relaxation);
  if (s.acceleration == "iqn-ils") return std::make_unique<IqnIls>(s.iqn);
  return std::make_unique<Aitken>(s.initial_relaxation, s.max_relaxation);
}

}  // namespace angio::coupler
