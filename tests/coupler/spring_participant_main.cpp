// Test participant: serves the spring beam or the rigid-wall solid of spring_participants.hpp
// over zenoh, so the coupler, the transport and the launcher can be tested end to end against a
// problem with an analytic solution, independently of the real solvers.
#include <chrono>

#include "angio/common/cli.hpp"
#include "angio/common/log.hpp"
#include "angio/participant/role_server.hpp"
#include "spring_participants.hpp"

using namespace angio;

int main(int argc, char** argv) {
  cli::Parser args("spring_participant", "Test participant with an analytic coupled solution.");
  args.add({"role", "ROLE", "beam or solid", ""});
  args.add({"delay", "SECONDS", "sleep this long in every solve (to test interruption)", "0"});
  args.add_common();
  return cli::run_main(args, argc, argv, [&] {
    const std::string role = args.get("role");
    cli::setup_logging(args, "spring-" + role);
    const participant::ServeOptions o = participant::serve_options(args, "spring_participant");
    const double delay = args.number("delay");
    if (role == "beam") {
      test::SpringBeam beam;
      beam.delay = delay;
      return participant::serve(beam, o);
    }
    test::WallSolid wall;
    return participant::serve(wall, o);
  });
}
