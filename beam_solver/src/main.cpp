// beam_solver: the stent side of the angioplasty co-simulation (docs/design.md §3).
//   beam_solver --scene FILE --run-dir DIR                       beam-only scene (standalone loop)
//   beam_solver --scene FILE --run-dir DIR --endpoint E --run-id ID   co-simulation (serves the
//                                                                      beam role to the coupler)
#include <filesystem>
#include <optional>

#include "angio/beam/participant.hpp"
#include "angio/beam/scene.hpp"
#include "angio/common/cli.hpp"
#include "angio/common/log.hpp"
#include "angio/participant/standalone.hpp"
#ifdef ANGIO_HAVE_ROLE_SERVER
#include "angio/participant/role_server.hpp"
#endif

int main(int argc, char** argv) {
  angio::cli::Parser cli("beam_solver",
                         "Stent as geometrically exact Simo-Reissner beams with elasto-plastic "
                         "bending.\nWithout --endpoint the scene is solved standalone (beam-only "
                         "scene); with --endpoint the beam role is served to the coupler.");
  cli.add_common();
  return angio::cli::run_main(cli, argc, argv, [&] {
    angio::cli::setup_logging(cli, "beam");
    angio::cli::require(cli, {"scene"});
    angio::beam::BeamScene scene = angio::beam::load_beam_scene(cli.get("scene"));
    if (cli.has("check")) return 0;  // the scene and the stent it generates are valid
    const std::string run_dir = cli.get("run-dir");
    const auto endpoint = cli.maybe("endpoint");
    const bool coupled = endpoint && !endpoint->empty();
#ifdef ANGIO_HAVE_ROLE_SERVER
    // the options (the run's key file among them) before any output: bad ones leave nothing behind
    std::optional<angio::participant::ServeOptions> serve_opts;
    if (coupled) serve_opts = angio::participant::serve_options(cli, "beam_solver 0.1");
#else
    if (coupled)
      throw angio::cli::UsageError("this beam_solver was built without the zenoh transport; --endpoint unsupported");
#endif
    std::filesystem::create_directories(run_dir);
    const auto time = scene.time;
    angio::beam::BeamSolverParticipant beam(std::move(scene), run_dir);
#ifdef ANGIO_HAVE_ROLE_SERVER
    if (coupled) return angio::participant::serve(beam, *serve_opts);  // co-simulation: the beam role
#endif
    return angio::participant::run_standalone(beam, time);
  });
}
