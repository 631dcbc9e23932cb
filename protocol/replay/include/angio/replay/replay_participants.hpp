// Participants that answer from a recording instead of solving (docs/design.md §4.6). They implement the ordinary
// participant interfaces, so the ordinary role server serves them, and the coupler cannot tell them from the real
// solvers. Each incoming request is checked against the recorded one (same verb, step, accept flag; interface vectors
// equal within a tolerance); a mismatch is an error naming the exchange.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "angio/participant/beam_participant.hpp"
#include "angio/participant/solid_participant.hpp"
#include "angio/recording/recording.hpp"

namespace angio::replay {

class ReplayMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "beam" → Role::Beam, "solid" → Role::Solid; anything else throws std::invalid_argument.
fb::Role role_from_name(const std::string& name);

// Walks through the recorded exchanges of one role in order.
class Cursor {
 public:
  Cursor(const recording::Recording& rec, fb::Role role);
  // Moves to the next exchange, which must carry a request of payload type `expected`, and
  // returns that (verified) request.
  const fb::Envelope& next(fb::Payload expected);
  // The recorded reply of the exchange `next` moved to.
  const fb::Envelope& reply() const;
  std::size_t position() const { return pos_; }

 private:
  std::vector<const recording::Exchange*> items_;
  std::size_t pos_ = 0;
  std::string run_id_;
  fb::Role role_;
};

// Largest |a − b| over all components, relative to max(1, max|b|): the comparison used for
// interface vectors (line loads, sample-point positions).
double relative_difference(const std::vector<participant::Vec3>& a, const std::vector<participant::Vec3>& b);

class ReplayBeam : public participant::BeamParticipant {
 public:
  ReplayBeam(const recording::Recording& rec, double tolerance);
  participant::SamplePoints sample_points() const override { return points_; }
  void begin_step(int step, double time) override;
  participant::SolveStats solve(const std::vector<participant::Vec3>& line_loads) override;
  void end_step(bool accept) override;
  void finish() override;

 private:
  Cursor cursor_;
  double tol_;
  participant::SamplePoints points_;
};

class ReplaySolid : public participant::SolidParticipant {
 public:
  ReplaySolid(const recording::Recording& rec, double tolerance);
  void begin_step(int step, double time) override;
  participant::SolveStats solve(const participant::SamplePoints& points, participant::ContactReply& reply,
                                double tolerance) override;
  void end_step(bool accept) override;
  void finish() override;

 private:
  Cursor cursor_;
  double tol_;
};

}  // namespace angio::replay
