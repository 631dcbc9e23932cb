// replay_participant: plays the beam or the solid role from a recording, so the coupler can be
// tested without real solvers; every request it receives is checked against the recorded one.
#include <chrono>

#include "angio/common/cli.hpp"
#include "angio/participant/role_server.hpp"
#include "angio/replay/replay_participants.hpp"

using namespace angio;

int main(int argc, char** argv) {
  cli::Parser args("replay_participant",
                   "Answers the coupler's requests for one role from a recording (see\n"
                   "scripts/make_recordings.sh), checking each request against the recorded one.");
  args.add({"recording", "FILE", "recording written by the coupler (--record)", ""});
  args.add({"role", "ROLE", "beam or solid", ""});
  args.add({"tolerance", "REL", "relative tolerance on interface vectors", "1e-9"});
  args.add_common();
  return cli::run_main(args, argc, argv, [&] {
    const std::string role = args.get("role");
    cli::setup_logging(args, "replay-" + role);
    const fb::Role r = replay::role_from_name(role);
    const auto rec = recording::read(args.get("recording"));
    participant::ServeOptions o =
        participant::serve_options(args, "replay_participant (" + args.get("recording") + ")");
    if (!args.has("run-id")) o.run_id = rec.run_id;
    const double tol = args.number("tolerance");
    if (r == fb::Role::Beam) {
      replay::ReplayBeam beam(rec, tol);
      return participant::serve(beam, o);
    }
    replay::ReplaySolid solid(rec, tol);
    return participant::serve(solid, o);
  });
}
