#include "angio/participant/remote.hpp"

#include "angio/common/clock.hpp"
#include "angio/common/log.hpp"
#include "angio/messages/builders.hpp"
#include "angio/messages/convert.hpp"
#include "angio/participant/keys.hpp"
#include "angio/recording/recording.hpp"
#include "angio/transport.hpp"

namespace angio::participant {

namespace {}  // namespace

Channel::Channel(const transport::Session& session, std::string run_id, fb::Role role,
                 std::chrono::milliseconds timeout, recording::Recorder* recorder, msg::RunKey key)
    : session_(session),
      run_id_(std::move(run_id)),
      role_(role),
      role_name_(msg::role_key(role)),
      timeout_(timeout),
      recorder_(recorder),
      key_(key) {}

bool Channel::alive(std::chrono::milliseconds timeout) const {
  return session_.liveliness_alive(keys::alive(run_id_, role_name_), timeout);
}

msg::Buffer Channel::call(const Build& build) {
  const std::uint64_t seq = sequence_.next();
  msg::Buffer request = build(msg::Header{run_id_, seq, fb::Role::Coupler});
  // the key's verb is the payload's (msg::request_verb, which the participant checks: one table)
  const char* v = msg::request_verb(fb::GetEnvelope(request.data())->payload_type());
  if (!v) throw std::logic_error("Channel::call: the message built is not a request");
  const std::string verb = v;
  const auto t0 = Clock::now();
  // Replies without the run's tag (a foreign replier on the key, or a participant started with
  // another key file) are skipped, counted and named if no authentic reply comes.
  int refused = 0;
  msg::Buffer reply;  // the envelope of the reply taken, copied out while the filter checks it
  const auto authentic = [&](transport::ByteView bytes) {
    const auto envelope = key_.verified(bytes);
    if (envelope) reply.assign(envelope->begin(), envelope->end());
    refused += envelope ? 0 : 1;
    return envelope.has_value();
  };
  try {
    session_.request(keys::request(run_id_, role_name_, verb), key_.seal(request), timeout_, authentic);
  } catch (const transport::RemoteError& e) {
    // our role servers answer only one request with a transport-level error: one they could not
    // authenticate (and no foreign replier's error is taken while ours may still come)
    throw ParticipantError("the " + role_name_ + " participant refused '" + verb + "': " + e.what() +
                           " (it does not read the run's key file; do all processes read the same "
                           "--key-file or <run-dir>/run.key?)");
  } catch (const transport::TimeoutError& e) {
    throw transport::TimeoutError(
        "the " + role_name_ + " participant did not answer '" + verb + "' within " +
        std::to_string(timeout_.count() / 1000.0) + " s (is it running? see its log): " + e.what() +
        (refused ? "; " + std::to_string(refused) +
                       " replies refused as not authenticated by the run's key (do all processes read "
                       "the same key file, --key-file or <run-dir>/run.key?)"
                 : std::string()));
  }
  timing_.round_trip = seconds_since(t0);
  timing_.solver_time = 0.0;
  if (recorder_) recorder_->add(role_, verb, request, reply);
  const fb::Envelope* env = nullptr;
  try {
    env = &msg::open(reply, run_id_);
    sequence_.check_reply(*env, seq);
  } catch (const msg::ProtocolError& e) {
    throw ParticipantError("bad reply from the " + role_name_ + " participant to '" + verb + "': " + e.what());
  }
  if (env->sender() != role_)
    throw ParticipantError("reply to '" + verb + "' came from role " + msg::role_name(env->sender()) + ", expected " +
                           role_name_);
  if (const auto* err = env->payload_as_Error())
    throw ParticipantError("the " + role_name_ + " participant failed on '" + verb +
                           "': " + flatbuffers::GetString(err->message()));
  return reply;
}

namespace {
// Opens a reply already verified by Channel::call and checks its payload type.
template <class T>
const T& reply_as(const msg::Buffer& b) {
  return msg::payload_as<T>(*flatbuffers::GetRoot<fb::Envelope>(b.data()));
}
// Messaging overhead of a solve = round trip minus the time the participant spent solving.
void account(Channel& ch, const fb::SolveStats* s) {
  ch.timing().solver_time = s ? s->wall_time() : 0.0;
  ch.add_messaging(ch.timing().round_trip - ch.timing().solver_time);
}
}  // namespace

std::string RemoteBeam::hello() {
  auto b = ch_.call([](const msg::Header& h) { return msg::hello(h, "coupler"); });
  const auto& r = reply_as<fb::HelloReply>(b);
  if (r.protocol_version() != msg::kProtocolVersion)
    throw ParticipantError("beam participant speaks protocol " + std::to_string(r.protocol_version()));
  points_ = msg::to_sample_points(r.sample_points());
  return flatbuffers::GetString(r.software());
}

void RemoteBeam::begin_step(int step, double time) {
  step_ = step;
  time_ = time;
  ch_.call([&](const msg::Header& h) { return msg::step_begin(h, step, time, 0.0); });
}

SolveStats RemoteBeam::solve(const std::vector<Vec3>& q) { return solve_(q, nullptr); }

SolveStats RemoteBeam::solve_with_planes(const std::vector<Vec3>& q, const ContactPlanes& planes) {
  return solve_(q, &planes);
}

SolveStats RemoteBeam::solve_(const std::vector<Vec3>& q, const ContactPlanes* planes) {
  auto b = ch_.call([&](const msg::Header& h) { return msg::beam_solve_request(h, step_, iteration_, q, planes); });
  const auto& r = reply_as<fb::BeamSolveReply>(b);
  account(ch_, r.stats());
  SamplePoints pts = msg::to_sample_points(r.sample_points());
  if (pts.size() != points_.size())
    throw ParticipantError("beam participant returned " + std::to_string(pts.size()) + " sample points, announced " +
                           std::to_string(points_.size()));
  points_ = std::move(pts);
  return msg::to_stats(r.stats());
}

SolveStats RemoteBeam::linear_response(const std::vector<double>& plane_shift, const std::vector<Vec3>& normal_turn,
                                       std::vector<Vec3>& dx) {
  auto b = ch_.call(
      [&](const msg::Header& h) { return msg::beam_linear_request(h, step_, iteration_, plane_shift, normal_turn); });
  const auto& r = reply_as<fb::BeamLinearReply>(b);
  account(ch_, r.stats());
  dx = msg::to_vec3s(r.dx());
  SolveStats s = msg::to_stats(r.stats());
  if (s.converged && dx.size() != points_.size())
    throw ParticipantError("beam participant returned " + std::to_string(dx.size()) + " displacements for " +
                           std::to_string(points_.size()) + " sample points");
  return s;
}

void RemoteBeam::end_step(bool accept) {
  ch_.call([&](const msg::Header& h) { return msg::step_end(h, step_, accept); });
}

void RemoteBeam::finish() {
  ch_.call([](const msg::Header& h) { return msg::shutdown(h, "run finished"); });
}

std::string RemoteSolid::hello() {
  auto b = ch_.call([](const msg::Header& h) { return msg::hello(h, "coupler"); });
  const auto& r = reply_as<fb::HelloReply>(b);
  if (r.protocol_version() != msg::kProtocolVersion)
    throw ParticipantError("solid participant speaks protocol " + std::to_string(r.protocol_version()));
  return flatbuffers::GetString(r.software());
}

void RemoteSolid::begin_step(int step, double time) {
  step_ = step;
  time_ = time;
  ch_.call([&](const msg::Header& h) { return msg::step_begin(h, step, time, 0.0); });
}

SolveStats RemoteSolid::solve(const SamplePoints& pts, ContactReply& reply, double tolerance) {
  auto b =
      ch_.call([&](const msg::Header& h) { return msg::solid_solve_request(h, step_, iteration_, pts, tolerance); });
  const auto& r = reply_as<fb::SolidSolveReply>(b);
  account(ch_, r.stats());
  reply = msg::to_contact(r);
  if (!pts.x.empty() && reply.line_loads.size() != pts.size())
    throw ParticipantError("solid participant returned " + std::to_string(reply.line_loads.size()) +
                           " line loads for " + std::to_string(pts.size()) + " sample points");
  return msg::to_stats(r.stats());
}

SolveStats RemoteSolid::linear_response(const std::vector<Vec3>& dx, std::vector<double>& plane_shift,
                                        std::vector<Vec3>& normal_turn) {
  auto b = ch_.call([&](const msg::Header& h) { return msg::solid_linear_request(h, step_, iteration_, dx); });
  const auto& r = reply_as<fb::SolidLinearReply>(b);
  account(ch_, r.stats());
  plane_shift = msg::to_doubles(r.plane_shift());
  normal_turn = msg::to_vec3s(r.normal_turn());
  return msg::to_stats(r.stats());
}

void RemoteSolid::end_step(bool accept) {
  ch_.call([&](const msg::Header& h) { return msg::step_end(h, step_, accept); });
}

void RemoteSolid::finish() {
  ch_.call([](const msg::Header& h) { return msg::shutdown(h, "run finished"); });
}

}  // namespace angio::participant
