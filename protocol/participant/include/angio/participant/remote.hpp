// The coupler's view of a participant in another process: RemoteBeam and RemoteSolid implement
// the participant interfaces by sending requests over zenoh, so the coupling loop is written once
// against BeamParticipant/SolidParticipant and can be tested with in-process participants.
#pragma once

#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>

#include "angio/messages/builders.hpp"
#include "angio/messages/seal.hpp"
#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"

namespace angio::transport {
class Session;
}
namespace angio::recording {
class Recorder;
}

namespace angio::participant {

// The participant answered a request with an Error message, or broke the protocol.
class ParticipantError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Timing of the last exchange, for the coupler's accounting of messaging overhead.
struct ExchangeTiming {
  double round_trip = 0.0;   // s, request sent → reply verified
  double solver_time = 0.0;  // s, as reported by the participant (solve replies only)
};

// One request/reply conversation with one role: sequence numbers, authentication (every request
// sealed with the run's key, only replies that carry its tag are taken), verification, recording
// (of the envelopes, without tags).
class Channel {
 public:
  Channel(const transport::Session& session, std::string run_id, fb::Role role, std::chrono::milliseconds timeout,
          recording::Recorder* recorder, msg::RunKey key);

  using Build = std::function<msg::Buffer(const msg::Header&)>;
  // Sends the request built by `build` to angio/<run>/<role>/<verb>, the verb being the payload's
  // (msg::request_verb); returns the verified reply
  // bytes (open them with msg::open). Throws ParticipantError on an Error reply and
  // transport::TimeoutError (with the role and verb) when no reply came in time.
  msg::Buffer call(const Build& build);
  // True while the participant's liveliness token is visible.
  bool alive(std::chrono::milliseconds timeout) const;
  // The reply timeout of later calls (the coupler's error path shortens it: a participant that went
  // silent once must not hold the shutdown for a second full timeout).
  void set_timeout(std::chrono::milliseconds timeout) { timeout_ = timeout; }

  const ExchangeTiming& timing() const { return timing_; }
  ExchangeTiming& timing() { return timing_; }
  const std::string& role_name() const { return role_name_; }
  // Accumulated s of solve round trips minus the participants' own solve time.
  double messaging_time() const { return messaging_; }
  void add_messaging(double s) { messaging_ += s; }

 private:
  const transport::Session& session_;
  std::string run_id_;
  fb::Role role_;
  std::string role_name_;
  std::chrono::milliseconds timeout_;
  recording::Recorder* recorder_;
  msg::RunKey key_;
  msg::Sequence sequence_;
  ExchangeTiming timing_;
  double messaging_ = 0.0;
};

class RemoteBeam : public BeamParticipant {
 public:
  explicit RemoteBeam(Channel& channel) : ch_(channel) {}
  // Handshake; returns the participant's software string and caches the sample points.
  std::string hello();
  SamplePoints sample_points() const override { return points_; }
  void begin_step(int step, double time) override;
  SolveStats solve(const std::vector<Vec3>& line_loads) override;
  SolveStats solve_with_planes(const std::vector<Vec3>& line_loads, const ContactPlanes& planes) override;
  SolveStats linear_response(const std::vector<double>& plane_shift, const std::vector<Vec3>& normal_turn,
                             std::vector<Vec3>& dx) override;
  void end_step(bool accept) override;
  void finish() override;  // sends Shutdown
  void set_iteration(int k) { iteration_ = k; }

 private:
  SolveStats solve_(const std::vector<Vec3>& line_loads, const ContactPlanes* planes);

  Channel& ch_;
  SamplePoints points_;
  int step_ = 0, iteration_ = 0;
  double time_ = 0.0;
};

class RemoteSolid : public SolidParticipant {
 public:
  explicit RemoteSolid(Channel& channel) : ch_(channel) {}
  std::string hello();
  void begin_step(int step, double time) override;
  SolveStats solve(const SamplePoints& beam_points, ContactReply& reply, double tolerance) override;
  SolveStats linear_response(const std::vector<Vec3>& dx, std::vector<double>& plane_shift,
                             std::vector<Vec3>& normal_turn) override;
  void end_step(bool accept) override;
  void finish() override;
  void set_iteration(int k) { iteration_ = k; }

 private:
  Channel& ch_;
  int step_ = 0, iteration_ = 0;
  double time_ = 0.0;
};

}  // namespace angio::participant
