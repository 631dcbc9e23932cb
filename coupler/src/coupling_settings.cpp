#include "angio/coupler/coupling_settings.hpp"

#include "angio/coupler/aitken.hpp"
#include "angio/coupler/iqn_imvj.hpp"
#include "angio/coupler/newton_krylov.hpp"

#include <nlohmann/json.hpp>

namespace angio::coupler {

CouplingSettings coupling_settings(const scene::Node& root) {
  CouplingSettings s;
  for (const char* part : {"stent", "solid"})
    if (auto p = root.optional(part); p && p->is_map() && p->has("initial_state")) s.synchronize = true;
  auto c = root.optional("coupling");
  if (!c) return s;
  c->check_keys();
  s.scheme = c->get<std::string>("scheme");
  s.surface_compliance = c->get<bool>("surface_compliance");
  if (s.surface_compliance && s.scheme != "robin")
    c->child("surface_compliance").fail("false (it applies only with coupling.scheme: robin)");
  s.acceleration = c->get<std::string>("acceleration");
  s.initial_relaxation = c->get<double>("initial_relaxation");
  s.max_relaxation = c->has("max_relaxation") ? c->get<double>("max_relaxation") : std::max(1.0, s.initial_relaxation);
  if (s.max_relaxation < s.initial_relaxation)
    c->child("max_relaxation").fail("a value >= coupling.initial_relaxation");
  if (auto iqn = c->optional("iqn")) {
    if (s.acceleration != "iqn-ils" && s.acceleration != "iqn-imvj")
      iqn->fail("no iqn section (it applies only with coupling.acceleration: iqn-ils or iqn-imvj)");
    iqn->check_keys();
    s.iqn.reused_steps = iqn->get<int>("reused_steps");
    s.iqn.max_columns = iqn->get<int>("max_columns");
    s.iqn.filter = iqn->get<double>("filter");
    s.iqn.stagnation = iqn->get<double>("stagnation");
  }
  s.iqn.initial_relaxation = s.initial_relaxation;
  if (s.acceleration == "newton-krylov" && s.scheme != "robin")
    c->child("acceleration").fail("another acceleration (newton-krylov needs coupling.scheme: robin)");
  if (auto nk = c->optional("newton_krylov")) {
    if (s.acceleration != "newton-krylov")
      nk->fail("no newton_krylov section (it applies only with coupling.acceleration: newton-krylov)");
    nk->check_keys();
    s.newton_krylov.max_products = nk->get<int>("max_products");
    s.newton_krylov.tolerance = nk->get<double>("tolerance");
  }
  s.max_iterations = c->get<int>("max_iterations");
  // below 1 (declared range): rel_tol 1 accepts a residual as large as the contact loads themselves,
  // every first iteration passes and the coupling does nothing (the solid's atol has the like check)
  s.rel_tol = c->get<double>("rel_tol");
  s.abs_tol = c->get<double>("abs_tol");
  if (s.rel_tol == 0.0 && s.abs_tol == 0.0)
    c->fail("a positive coupling.rel_tol or coupling.abs_tol (both are 0: nothing can converge)");
  s.strict = c->get<bool>("strict");
  s.restart_growth = c->get<double>("restart_growth");
  if (s.restart_growth != 0.0 && !(s.restart_growth > 1.0))
    c->child("restart_growth").fail("0 (never restart) or a factor > 1");
  s.stall_iterations = c->get<int>("stall_iterations");
  s.prediction = c->get<std::string>("prediction");
  s.record = c->get<bool>("record");
  s.inexact_solid = c->get<double>("inexact_solid");
  return s;
}

std::string settings_json(const CouplingSettings& s) {
  nlohmann::ordered_json j = {{"scheme", s.scheme},
                              {"surface_compliance", s.surface_compliance},
                              {"acceleration", s.acceleration},
                              {"initial_relaxation", s.initial_relaxation},
                              {"max_relaxation", s.max_relaxation},
                              {"max_iterations", s.max_iterations},
                              {"rel_tol", s.rel_tol},
                              {"abs_tol", s.abs_tol},
                              {"strict", s.strict},
                              {"restart_growth", s.restart_growth},
                              {"stall_iterations", s.stall_iterations},
                              {"prediction", s.prediction},
                              {"record", s.record},
                              {"inexact_solid", s.inexact_solid}};
  if (s.acceleration == "iqn-ils" || s.acceleration == "iqn-imvj")
    j["iqn"] = {{"reused_steps", s.iqn.reused_steps},
                {"max_columns", s.iqn.max_columns},
                {"filter", s.iqn.filter},
                {"stagnation", s.iqn.stagnation}};
  if (s.acceleration == "newton-krylov")
    j["newton_krylov"] = {{"max_products", s.newton_krylov.max_products}, {"tolerance", s.newton_krylov.tolerance}};
  return j.dump();
}

std::unique_ptr<Acceleration> make_acceleration(const CouplingSettings& s) {
  if (s.acceleration == "constant") return std::make_unique<ConstantRelaxation>(s.initial_relaxation);
  if (s.acceleration == "iqn-ils") return std::make_unique<IqnIls>(s.iqn);
  if (s.acceleration == "iqn-imvj") return std::make_unique<IqnImvj>(s.iqn);
  if (s.acceleration == "newton-krylov") return std::make_unique<NewtonKrylov>(s.newton_krylov);
  return std::make_unique<Aitken>(s.initial_relaxation, s.max_relaxation);
}

}  // namespace angio::coupler
