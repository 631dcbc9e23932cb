// replay_driver: plays the coupler for ONE real participant. It sends the recorded requests of
// that role verbatim and compares the participant's replies with the recorded replies within a
// tolerance (the check that a solver still reproduces a recorded co-simulation).
#include <algorithm>
#include <chrono>
#include <string>

#include "angio/common/cli.hpp"
#include "angio/common/log.hpp"
#include "angio/messages/convert.hpp"
#include "angio/messages/seal.hpp"
#include "angio/participant/keys.hpp"
#include "angio/participant/role_server.hpp"
#include "angio/replay/replay_participants.hpp"
#include "angio/transport.hpp"

using namespace angio;

namespace {

// Relative deviation of a live reply from the recorded one, on the interface vectors the
// coupler consumes; throws if the kind of reply differs.
double deviation(const fb::Envelope& live, const fb::Envelope& rec) {
  if (live.payload_type() != rec.payload_type())
    throw replay::ReplayMismatch(std::string("reply is a ") + msg::payload_name(live.payload_type()) + ", recorded a " +
                                 msg::payload_name(rec.payload_type()));
  if (auto* b = live.payload_as_BeamSolveReply()) {
    auto* r = rec.payload_as_BeamSolveReply();
    if (b->stats()->converged() != r->stats()->converged())
      throw replay::ReplayMismatch("Newton convergence differs from the recording");
    return replay::relative_difference(msg::to_sample_points(b->sample_points()).x,
                                       msg::to_sample_points(r->sample_points()).x);
  }
  if (auto* s = live.payload_as_SolidSolveReply()) {
    auto* r = rec.payload_as_SolidSolveReply();
    if (s->stats()->converged() != r->stats()->converged())
      throw replay::ReplayMismatch("Newton convergence differs from the recording");
    return replay::relative_difference(msg::to_vec3s(s->line_loads()), msg::to_vec3s(r->line_loads()));
  }
  return 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Parser args("replay_driver",
                   "Drives one real participant with the recorded requests of its role and\n"
                   "compares its replies with the recorded ones.");
  args.add({"recording", "FILE", "recording written by the coupler (--record)", ""});
  args.add({"role", "ROLE", "beam or solid", ""});
  args.add({"tolerance", "REL", "relative tolerance on interface vectors", "1e-6"});
  args.add_common();
  return cli::run_main(args, argc, argv, [&] {
    cli::setup_logging(args, "replay-driver");
    const std::string role = args.get("role");
    const fb::Role r = replay::role_from_name(role);
    const auto rec = recording::read(args.get("recording"));
    const double tol = args.number("tolerance");
    const auto timeout = std::chrono::milliseconds(static_cast<long>(1000 * args.number("timeout")));
    // the participant driven must read the same key file (--key-file, or <run-dir>/run.key of both)
    const msg::RunKey key = participant::run_key(args);
    msg::Buffer live_bytes;  // the envelope of the authentic reply, copied out by the filter
    const auto authentic = [&](transport::ByteView b) {
      const auto envelope = key.verified(b);
      if (envelope) live_bytes.assign(envelope->begin(), envelope->end());
      return envelope.has_value();
    };
    auto session = transport::Session::open({{args.get("endpoint")}, {}});
    auto token = session.declare_liveliness_token(participant::keys::alive(rec.run_id, "coupler"));
    double worst = 0.0;
    std::size_t n = 0;
    for (const auto& e : rec.exchanges) {
      if (e.role != r) continue;
      // The recording keeps the verb the coupler sent the request to.
      const std::string key_expr = participant::keys::request(rec.run_id, role, e.verb);
      session.request(key_expr, key.seal(e.request), timeout, authentic);
      const fb::Envelope& live = msg::open(live_bytes, rec.run_id);
      if (const auto* err = live.payload_as_Error())
        throw replay::ReplayMismatch("exchange " + std::to_string(n) +
                                     ": participant error: " + flatbuffers::GetString(err->message()));
      const double d = deviation(live, msg::open(e.reply, rec.run_id));
      worst = std::max(worst, d);
      if (!(d <= tol))
        throw replay::ReplayMismatch("exchange " + std::to_string(n) + " (" + e.verb + "): reply deviates by " +
                                     std::to_string(d) + " (relative), tolerance " + std::to_string(tol));
      ++n;
    }
    LOG_INFO(n << " exchanges replayed against the " << role << " participant; largest relative deviation " << worst
               << " (tolerance " << tol << ")");
    return 0;
  });
}
