// coupler: owns the load steps and the coupling iteration of a run (Dirichlet–Neumann or robin,
// coupling_loop.hpp); talks to beam_solver and solid_solver over zenoh and never touches element
// data (docs/design.md §3).
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <memory>
#include <optional>

#include "angio/common/cli.hpp"
#include "angio/common/log.hpp"
#include "angio/coupler/coupling_loop.hpp"
#include "angio/coupler/step_csv.hpp"
#include "angio/coupler/summary.hpp"
#include "angio/participant/keys.hpp"
#include "angio/participant/remote.hpp"
#include "angio/participant/role_server.hpp"
#include "angio/recording/recording.hpp"
#include "angio/scene/load_curve.hpp"
#include "angio/transport.hpp"

using namespace angio;
namespace fs = std::filesystem;

namespace {
// Ctrl-C (SIGINT, forwarded by the launcher): finish the step under way, then stop cleanly (the
// participants are shut down and write their summaries). A second signal or SIGTERM stops at once.
volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_sigint(int) {
  if (g_stop) std::_Exit(130);
  g_stop = 1;
}

// coupling_summary.json (summary.hpp); a summary that cannot be written is logged, not thrown, so
// that a failed run still ends with its own error and exit code
void write_summary(const fs::path& path, const std::string& status, const std::string& error,
                   const coupler::RunReport& run, double messaging) {
  if (!coupler::write_coupling_summary(path.string(), status, error, run, messaging))
    LOG_ERROR("cannot write " << path.string());
}

int run(const cli::Parser& args) {
  const scene::Node root = scene::load_scene(args.get("scene"));
  const scene::TimeSettings time = scene::time_settings(root);
  const coupler::CouplingSettings settings = coupler::coupling_settings(root);
  const scene::LoadCurves curves = scene::load_curves(root);
  // the balloon pressure (column `pressure` of coupling.csv): balloon.pressure of the scene, 0 without
  scene::ScaledCurve balloon_pressure;
  if (const auto b = root.optional("balloon"); b && b->has("pressure"))
    balloon_pressure = scene::scaled_curve(*b, "pressure", curves);
  if (args.has("print-settings")) {  // the coupling settings as run, defaults filled in (scripts read them)
    std::printf("%s\n", coupler::settings_json(settings).c_str());
    return 0;
  }
  if (args.has("check")) return 0;  // time, load curves and coupling settings are valid
  const fs::path run_dir = args.get("run-dir");
  // the run's key before anything is written: a missing or loose key file is bad input (exit 2)
  const msg::RunKey key = participant::run_key(args);
  fs::create_directories(run_dir);
  const std::string run_id = args.get("run-id");
  const auto timeout = std::chrono::milliseconds(static_cast<long>(1000 * args.number("timeout")));
  std::signal(SIGINT, on_sigint);

  std::unique_ptr<recording::Recorder> recorder;
  if (settings.record || args.has("record"))
    recorder = std::make_unique<recording::Recorder>((run_dir / "exchanges.angiorec").string(), run_id);

  auto session = transport::Session::open({{args.get("endpoint")}, {}});
  auto token = session.declare_liveliness_token(participant::keys::alive(run_id, "coupler"));
  participant::Channel beam_ch(session, run_id, fb::Role::Beam, timeout, recorder.get(), key);
  participant::Channel solid_ch(session, run_id, fb::Role::Solid, timeout, recorder.get(), key);
  participant::RemoteBeam beam(beam_ch);
  participant::RemoteSolid solid(solid_ch);

  coupler::StepCsv csv((run_dir / "coupling.csv").string());
  auto acc = coupler::make_acceleration(settings);
  coupler::RunReport report;
  double messaging_before = 0.0;
  try {
    // the handshake inside the error path: a participant that is missing, silent or without the
    // run's key fails the run like any later exchange (summary "failed", exit 3)
    const std::string beam_sw = beam.hello();
    const std::string solid_sw = solid.hello();
    LOG_INFO("run " << run_id << ": beam " << beam_sw << " (" << beam.sample_points().size()
                    << " contact sample points), solid " << solid_sw << "; " << time.steps
                    << " steps to t = " << time.end << " s, " << settings.scheme << " coupling with "
                    << settings.acceleration << " acceleration");
    report = coupler::run_coupled(beam, solid, time, settings, *acc, [&](const coupler::StepReport& r) {
      const double messaging = beam_ch.messaging_time() + solid_ch.messaging_time();
      const double step_messaging = messaging - messaging_before;
      messaging_before = messaging;
      const double p = balloon_pressure.at(r.time);
      csv.write(r, p, step_messaging);
      LOG_INFO("step " << r.step << " t = " << r.time << " s p = " << p << " MPa: " << r.iterations
                       << " coupling iterations, residual " << (r.residuals.empty() ? 0.0 : r.residuals.back())
                       << ", omega " << r.omega << ", " << r.contact.n_active << " active, wall "
                       << std::setprecision(3) << r.wall_time << " s (beam " << r.beam_time << ", solid "
                       << r.solid_time << ")");
      if (g_stop) throw coupler::StopRequested{};
    });
  } catch (const std::exception& e) {
    LOG_ERROR(e.what());
    write_summary(run_dir / "coupling_summary.json", "failed", e.what(), report,
                  beam_ch.messaging_time() + solid_ch.messaging_time());
    // Tell the participants to finish so they close their output cleanly; their own errors are
    // secondary to the one reported above.
    auto quietly = [](const std::function<void()>& f) {
      try {
        f();
      } catch (const std::exception& e) {
        LOG_DEBUG("while shutting down: " << e.what());
      }
    };
    // a participant that is silent (frozen or dead) would hold each of these for a full timeout
    const auto grace = std::min(timeout, std::chrono::milliseconds(2000));
    beam_ch.set_timeout(grace);
    solid_ch.set_timeout(grace);
    quietly([&] { beam.finish(); });
    quietly([&] { solid.finish(); });
    return 3;
  }
  beam.finish();
  solid.finish();
  const double messaging = beam_ch.messaging_time() + solid_ch.messaging_time();
  if (report.interrupted) {
    const std::string why = "interrupted (SIGINT) after step " + std::to_string(report.steps) +
                            "; the participants were shut down and wrote their results so far";
    LOG_WARN(why);
    write_summary(run_dir / "coupling_summary.json", "interrupted", why, report, messaging);
    return 130;
  }
  write_summary(run_dir / "coupling_summary.json", "ok", "", report, messaging);
  LOG_INFO("done: " << report.steps << " steps, coupling iterations mean " << report.mean_iterations() << " max "
                    << report.max_iterations << ", wall " << report.wall_time << " s, messaging "
                    << 100.0 * messaging / std::max(report.wall_time, 1e-12) << " %");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Parser args("coupler",
                   "Runs the load steps and the coupling iterations (scene coupling.scheme and\n"
                   "coupling.acceleration) of a co-simulation; beam_solver and solid_solver connect\n"
                   "to --endpoint.");
  args.add_common();
  args.add({"record", "", "record every exchanged message into <run-dir>/exchanges.angiorec", ""});
  args.add(
      {"print-settings", "", "print the scene's coupling settings with every default filled in (JSON) and exit", ""});
  return cli::run_main(args, argc, argv, [&] {
    cli::setup_logging(args, "coupler");
    if (args.has("check") || args.has("print-settings"))
      cli::require(args, {"scene"});
    else
      cli::require(args, {"scene", "endpoint"});
    return run(args);
  });
}
