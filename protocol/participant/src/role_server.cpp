#include "angio/participant/role_server.hpp"

#include <chrono>
#include <filesystem>
#include <functional>

#include "angio/common/clock.hpp"
#include "angio/common/log.hpp"
#include "angio/messages/builders.hpp"
#include "angio/messages/convert.hpp"
#include "angio/messages/step_state.hpp"
#include "angio/participant/keys.hpp"
#include "angio/transport.hpp"

namespace angio::participant {
namespace {

// Turns one verified request into a reply; sets `stop` after a Shutdown.
using Dispatch = std::function<msg::Buffer(const fb::Envelope&, const msg::Header&, bool& stop)>;

// The loop shared by every role: receive, verify, check the sequence, dispatch, reply; watch the
// coupler's liveliness token and the silence timeout so that a vanished coupler ends the process
// with a clear error instead of a hang.
int serve_role(fb::Role role, const ServeOptions& o, const Dispatch& dispatch) {
  if (!o.key) throw std::logic_error("serve: ServeOptions without the run's key (use serve_options)");
  const std::string name = msg::role_key(role);
  std::optional<transport::Session> session;
  try {
    session.emplace(transport::Session::open({{}, {o.endpoint}}));
  } catch (const transport::TransportError& e) {
    LOG_ERROR("cannot open the zenoh session to " << o.endpoint << ": " << e.what());
    return 5;
  }
  auto token = session->declare_liveliness_token(keys::alive(o.run_id, name));
  auto coupler = session->watch_liveliness(keys::alive(o.run_id, "coupler"));
  auto queryable = session->declare_queryable(keys::serve(o.run_id, name));
  LOG_DEBUG("serving " << keys::serve(o.run_id, name) << " via " << o.endpoint);

  msg::Sequence sequence;
  msg::StepState state;
  bool coupler_seen = false;
  long refused = 0;
  auto last_heard = Clock::now();
  for (;;) {
    auto q = queryable.recv(std::chrono::milliseconds(200));
    if (!q) {
      while (auto ev = coupler.recv(std::chrono::milliseconds(1))) {
        if (ev->alive) {
          coupler_seen = true;
        } else if (coupler_seen) {
          LOG_ERROR("the coupler disappeared (its liveliness token " << ev->key << " is gone); exiting");
          return 4;
        }
      }
      // The coupler itself waits up to --timeout for the other participant before it gives up and
      // names it; waiting twice that (plus the coupler's shutdown grace) leaves the diagnosis to
      // the coupler, which knows who went silent. A frozen or dead coupler is caught earlier by
      // its liveliness token above.
      if (Clock::now() - last_heard > 2 * o.timeout + std::chrono::seconds(5)) {
        LOG_ERROR("no request from the coupler for " << seconds_since(last_heard)
                                                     << " s (2 x --timeout + 5 s); exiting");
        return 4;
      }
      continue;
    }
    // A request without the run's tag comes from a process that cannot read the run's key file:
    // it gets a transport-level error, never a message sealed with our key, and does not count as
    // the coupler being heard. The log names the first refusals, then every 1000th (a flood of
    // forged requests must not fill the disk).
    std::span<const std::uint8_t> bytes;
    try {
      bytes = o.key->unseal(q->payload());
    } catch (const msg::ProtocolError& e) {
      if (++refused <= 10 || refused % 1000 == 0)
        LOG_WARN("request on " << q->key() << " refused (" << refused << " so far): " << e.what());
      q->reply_error("not authenticated");
      continue;
    }
    last_heard = Clock::now();
    msg::Header h{o.run_id, 0, role};
    bool stop = false;
    try {
      const fb::Envelope& env = msg::open(bytes, o.run_id);
      h.sequence = env.sequence();
      msg::check_verb(env, q->key());
      sequence.check_request(env);
      state.check(env);
      q->reply(o.key->seal(dispatch(env, h, stop)));
    } catch (const std::exception& e) {
      // A bad message or a failing solver is answered with an Error; the coupler decides.
      LOG_ERROR("request on " << q->key() << " failed: " << e.what());
      q->reply(o.key->seal(msg::error(h, e.what())));
    }
    if (stop) return 0;
  }
}

msg::Buffer common(const fb::Envelope& env, const msg::Header& h, bool& stop, const std::function<void()>& finish) {
  if (env.payload_type() == fb::Payload::Shutdown) {
    LOG_DEBUG("shutdown: " << flatbuffers::GetString(env.payload_as_Shutdown()->reason()));
    finish();
    stop = true;
    return msg::ack(h);
  }
  throw msg::ProtocolError(std::string("unexpected ") + msg::payload_name(env.payload_type()) + " request");
}

}  // namespace

msg::RunKey run_key(const cli::Parser& args) {
  const std::string file = args.maybe("key-file").value_or("");
  return msg::RunKey::read(file.empty() ? std::filesystem::path(args.get("run-dir")) / "run.key"
                                        : std::filesystem::path(file));
}

ServeOptions serve_options(const cli::Parser& args, std::string software) {
  ServeOptions o;
  o.endpoint = args.get("endpoint");
  o.run_id = args.get("run-id");
  o.timeout = std::chrono::milliseconds(static_cast<long>(1000.0 * args.number("timeout")));
  o.software = std::move(software);
  o.key = run_key(args);
  return o;
}

int serve(BeamParticipant& beam, const ServeOptions& o) {
  return serve_role(fb::Role::Beam, o, [&](const fb::Envelope& env, const msg::Header& h, bool& stop) {
    switch (env.payload_type()) {
      case fb::Payload::Hello: {
        auto pts = beam.sample_points();
        return msg::hello_reply(h, o.software, &pts);
      }
      case fb::Payload::StepBegin: {
        const auto& s = *env.payload_as_StepBegin();
        beam.begin_step(static_cast<int>(s.step()), s.time());
        return msg::ack(h);
      }
      case fb::Payload::BeamSolveRequest: {
        const auto& r = *env.payload_as_BeamSolveRequest();
        auto q = msg::to_vec3s(r.line_loads());
        const std::size_t n = beam.sample_points().size();
        if (q.size() != n)
          throw msg::ProtocolError("BeamSolveRequest carries " + std::to_string(q.size()) +
                                   " line loads, the stent has " + std::to_string(n) + " sample points");
        // Robin mode when the request carries contact planes (all three vectors, K per point).
        ContactPlanes planes;
        planes.s = msg::to_vec3s(r.surface_points());
        planes.n = msg::to_vec3s(r.normals());
        planes.eps = msg::to_doubles(r.penalty());
        planes.g0 = r.regularization();
        const bool robin = !planes.eps.empty();
        if ((robin || !planes.s.empty() || !planes.n.empty()) &&
            (planes_per_point(planes.eps.size(), n) == 0 || planes.s.size() != planes.eps.size() ||
             planes.n.size() != planes.eps.size()))
          throw msg::ProtocolError("BeamSolveRequest carries contact planes of sizes " +
                                   std::to_string(planes.s.size()) + "/" + std::to_string(planes.n.size()) + "/" +
                                   std::to_string(planes.eps.size()) + ", expected K x " + std::to_string(n) + " each");
        const auto t0 = Clock::now();
        SolveStats stats = robin ? beam.solve_with_planes(q, planes) : beam.solve(q);
        return msg::beam_solve_reply(h, stats, seconds_since(t0), beam.sample_points());
      }
      case fb::Payload::BeamLinearRequest: {
        const auto& r = *env.payload_as_BeamLinearRequest();
        const auto shift = msg::to_doubles(r.plane_shift());
        const auto turn = msg::to_vec3s(r.normal_turn());
        std::vector<Vec3> dx;
        const auto t0 = Clock::now();
        SolveStats stats = beam.linear_response(shift, turn, dx);
        return msg::beam_linear_reply(h, stats, seconds_since(t0), dx);
      }
      case fb::Payload::StepEnd:
        beam.end_step(env.payload_as_StepEnd()->accept());
        return msg::ack(h);
      default:
        return common(env, h, stop, [&] { beam.finish(); });
    }
  });
}

int serve(SolidParticipant& solid, const ServeOptions& o) {
  return serve_role(fb::Role::Solid, o, [&](const fb::Envelope& env, const msg::Header& h, bool& stop) {
    switch (env.payload_type()) {
      case fb::Payload::Hello:
        return msg::hello_reply(h, o.software, nullptr);
      case fb::Payload::StepBegin: {
        const auto& s = *env.payload_as_StepBegin();
        solid.begin_step(static_cast<int>(s.step()), s.time());
        return msg::ack(h);
      }
      case fb::Payload::SolidSolveRequest: {
        const auto& r = *env.payload_as_SolidSolveRequest();
        SamplePoints pts = msg::to_sample_points(r.sample_points());
        ContactReply reply;
        const auto t0 = Clock::now();
        SolveStats stats = solid.solve(pts, reply, r.tolerance());  // checked by msg::StepState
        return msg::solid_solve_reply(h, stats, seconds_since(t0), reply);
      }
      case fb::Payload::SolidLinearRequest: {
        const auto dx = msg::to_vec3s(env.payload_as_SolidLinearRequest()->dx());
        std::vector<double> shift;
        std::vector<Vec3> turn;
        const auto t0 = Clock::now();
        SolveStats stats = solid.linear_response(dx, shift, turn);
        return msg::solid_linear_reply(h, stats, seconds_since(t0), shift, turn);
      }
      case fb::Payload::StepEnd:
        solid.end_step(env.payload_as_StepEnd()->accept());
        return msg::ack(h);
      default:
        return common(env, h, stop, [&] { solid.finish(); });
    }
  });
}

}  // namespace angio::participant
