#include "angio/coupler/summary.hpp"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

namespace angio::coupler {

std::string coupling_summary_json(const std::string& status, const std::string& error, const RunReport& run,
                                  double messaging_time) {
  using nlohmann::ordered_json;
  auto finite = [](double v) { return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr); };
  ordered_json j;
  j["status"] = status;
  j["error"] = error;
  j["steps"] = run.steps;
  j["rejected_attempts"] = run.rejected_attempts;
  j["prediction_retries"] = run.prediction_retries;
  j["coupling_iterations_total"] = run.total_iterations;
  j["coupling_iterations_mean"] = finite(run.mean_iterations());
  j["coupling_iterations_max"] = run.max_iterations;
  j["wall_time"] = finite(run.wall_time);
  j["beam_time"] = finite(run.beam_time);
  j["solid_time"] = finite(run.solid_time);
  j["messaging_time"] = finite(messaging_time);
  j["messaging_share"] = finite(run.wall_time > 0 ? messaging_time / run.wall_time : 0.0);
  j["jacobian_products"] = run.products;  // newton-krylov: products of every attempt
  j["product_time"] = finite(run.product_time);
  // an exception text with invalid UTF-8 is replaced character-wise, not an exception here
  return j.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n";
}

bool write_coupling_summary(const std::string& path, const std::string& status, const std::string& error,
                            const RunReport& run, double messaging_time) {
  std::ofstream o(path);
  if (!o) return false;
  o << coupling_summary_json(status, error, run, messaging_time);
  return static_cast<bool>(o);
}

}  // namespace angio::coupler
