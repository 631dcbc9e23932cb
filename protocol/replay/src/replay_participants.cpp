#include "angio/replay/replay_participants.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "angio/messages/convert.hpp"

namespace angio::replay {

fb::Role role_from_name(const std::string& name) {
  if (name == "beam") return fb::Role::Beam;
  if (name == "solid") return fb::Role::Solid;
  throw std::invalid_argument("--role: expected beam or solid, got '" + name + "'");
}

Cursor::Cursor(const recording::Recording& rec, fb::Role role) : run_id_(rec.run_id), role_(role) {
  for (const auto& e : rec.exchanges)
    if (e.role == role) items_.push_back(&e);
  // The handshake is answered from the recording at construction time by the participants.
}

const fb::Envelope& Cursor::next(fb::Payload expected) {
  if (pos_ >= items_.size())
    throw ReplayMismatch(std::string("received a ") + msg::payload_name(expected) +
                         " request after the end of the recording (" + std::to_string(items_.size()) +
                         " exchanges of role " + msg::role_name(role_) + ")");
  const fb::Envelope& req = msg::open(items_[pos_]->request, run_id_);
  if (req.payload_type() != expected)
    throw ReplayMismatch("exchange " + std::to_string(pos_) + " of role " + msg::role_name(role_) + ": received a " +
                         msg::payload_name(expected) + " request, recorded a " + msg::payload_name(req.payload_type()));
  ++pos_;
  return req;
}

const fb::Envelope& Cursor::reply() const { return msg::open(items_.at(pos_ - 1)->reply, run_id_); }

double relative_difference(const std::vector<participant::Vec3>& a, const std::vector<participant::Vec3>& b) {
  if (a.size() != b.size()) return INFINITY;
  double scale = 1.0, diff = 0.0;
  for (std::size_t i = 0; i < b.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      scale = std::max(scale, std::abs(b[i][d]));
      diff = std::max(diff, std::abs(a[i][d] - b[i][d]));
    }
  return diff / scale;
}

namespace {

void check_step(const Cursor& c, const fb::StepBegin& rec, int step, double time) {
  if (static_cast<int>(rec.step()) != step || std::abs(rec.time() - time) > 1e-12 * (1 + std::abs(time))) {
    std::ostringstream os;
    os << "exchange " << c.position() - 1 << ": StepBegin(step " << step << ", t " << time
       << ") but recorded StepBegin(step " << rec.step() << ", t " << rec.time() << ")";
    throw ReplayMismatch(os.str());
  }
}

void check_end(const Cursor& c, const fb::StepEnd& rec, bool accept) {
  if (rec.accept() != accept)
    throw ReplayMismatch("exchange " + std::to_string(c.position() - 1) +
                         ": StepEnd(accept = " + (accept ? "true" : "false") + ") but the recording " +
                         (rec.accept() ? "accepted" : "rejected") + " the step");
}

void check_vectors(const Cursor& c, const char* what, const std::vector<participant::Vec3>& got,
                   const std::vector<participant::Vec3>& rec, double tol) {
  const double d = relative_difference(got, rec);
  if (!(d <= tol)) {
    std::ostringstream os;
    os << "exchange " << c.position() - 1 << ": " << what << " differ from the recording by " << d
       << " (relative), tolerance " << tol;
    if (got.size() != rec.size()) os << " (" << got.size() << " vs " << rec.size() << " points)";
    throw ReplayMismatch(os.str());
  }
}

// A scalar of the request (e.g. the solve tolerance), compared relative to max(1, |recorded|).
void check_scalar(const Cursor& c, const char* what, double got, double rec, double tol) {
  const double d = std::abs(got - rec) / std::max(1.0, std::abs(rec));
  if (!(d <= tol)) {
    std::ostringstream os;
    os << "exchange " << c.position() - 1 << ": " << what << " " << got << " but recorded " << rec << ", tolerance "
       << tol;
    throw ReplayMismatch(os.str());
  }
}

}  // namespace

ReplayBeam::ReplayBeam(const recording::Recording& rec, double tol) : cursor_(rec, fb::Role::Beam), tol_(tol) {
  cursor_.next(fb::Payload::Hello);
  points_ = msg::to_sample_points(msg::payload_as<fb::HelloReply>(cursor_.reply()).sample_points());
}

void ReplayBeam::begin_step(int step, double time) {
  check_step(cursor_, *cursor_.next(fb::Payload::StepBegin).payload_as_StepBegin(), step, time);
}

participant::SolveStats ReplayBeam::solve(const std::vector<participant::Vec3>& q) {
  const auto& req = *cursor_.next(fb::Payload::BeamSolveRequest).payload_as_BeamSolveRequest();
  check_vectors(cursor_, "beam line loads", q, msg::to_vec3s(req.line_loads()), tol_);
  const auto& r = msg::payload_as<fb::BeamSolveReply>(cursor_.reply());
  points_ = msg::to_sample_points(r.sample_points());
  return msg::to_stats(r.stats());
}

void ReplayBeam::end_step(bool accept) {
  check_end(cursor_, *cursor_.next(fb::Payload::StepEnd).payload_as_StepEnd(), accept);
}

void ReplayBeam::finish() { cursor_.next(fb::Payload::Shutdown); }

ReplaySolid::ReplaySolid(const recording::Recording& rec, double tol) : cursor_(rec, fb::Role::Solid), tol_(tol) {
  cursor_.next(fb::Payload::Hello);
}

void ReplaySolid::begin_step(int step, double time) {
  check_step(cursor_, *cursor_.next(fb::Payload::StepBegin).payload_as_StepBegin(), step, time);
}

participant::SolveStats ReplaySolid::solve(const participant::SamplePoints& pts, participant::ContactReply& reply,
                                           double tolerance) {
  const auto& req = *cursor_.next(fb::Payload::SolidSolveRequest).payload_as_SolidSolveRequest();
  const participant::SamplePoints rec = msg::to_sample_points(req.sample_points());
  check_vectors(cursor_, "sample-point positions", pts.x, rec.x, tol_);
  if (pts.w.size() != rec.w.size() || pts.radius.size() != rec.radius.size())
    throw ReplayMismatch("exchange " + std::to_string(cursor_.position() - 1) + ": " + std::to_string(pts.w.size()) +
                         " sample-point weights/radii but the recording has " + std::to_string(rec.w.size()));
  for (std::size_t i = 0; i < rec.w.size(); ++i) {
    check_scalar(cursor_, "sample-point weight", pts.w[i], rec.w[i], tol_);
    check_scalar(cursor_, "sample-point radius", pts.radius[i], rec.radius[i], tol_);
  }
  check_scalar(cursor_, "solve tolerance", tolerance, req.tolerance(), tol_);
  const auto& r = msg::payload_as<fb::SolidSolveReply>(cursor_.reply());
  reply = msg::to_contact(r);
  return msg::to_stats(r.stats());
}

void ReplaySolid::end_step(bool accept) {
  check_end(cursor_, *cursor_.next(fb::Payload::StepEnd).payload_as_StepEnd(), accept);
}

void ReplaySolid::finish() { cursor_.next(fb::Payload::Shutdown); }

}  // namespace angio::replay
