// beam_solver: the stent side of the angioplasty co-simulation (DESIGN §2).
//   beam_solver --scene FILE --run-dir DIR                       beam-only scene (standalone loop)
//   beam_solver --scene FILE --run-dir DIR --endpoint E --run-id ID   co-simulation (serves the
//                                                                      beam role to the coupler)
#include <filesystem>

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
    std::filesystem::create_directories(run_dir);
    const auto time = scene.time;
    angio::beam::BeamSolverParticipant beam(std::move(scene), run_dir);
    const auto endpoint = cli.maybe("endpoint");
    if (endpoint && !endpoint->empty()) {
      // ---- co-simulation: serve the beam role to the coupler ----
#ifdef ANGIO_HAVE_ROLE_SERVER
      const auto o = angio::participant::serve_options(cli, "beam_solver 0.1");
      return angio::participant::serve(beam, o);
#else
      throw angio::cli::UsageError("this beam_solver was built without the zenoh transport; --endpoint unsupported");
#endif
    }
    return angio::participant::run_standalone(beam, time);
  });
}
