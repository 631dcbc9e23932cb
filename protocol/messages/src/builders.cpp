#include "angio/messages/builders.hpp"

namespace angio::msg {
namespace {

using flatbuffers::FlatBufferBuilder;
using flatbuffers::Offset;

Buffer finish(FlatBufferBuilder& b, const Header& h, fb::Payload type, Offset<void> payload) {
  auto run = b.CreateString(h.run_id);
  auto env = fb::CreateEnvelope(b, kProtocolVersion, run, h.sequence, h.sender, type, payload);
  fb::FinishEnvelopeBuffer(b, env);
  return Buffer(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
}

Offset<flatbuffers::Vector<const fb::Vec3*>> vec3s(FlatBufferBuilder& b, const std::vector<participant::Vec3>& v) {
  // participant::Vec3 is std::array<double,3>: same layout as the fb::Vec3 struct.
  static_assert(sizeof(fb::Vec3) == sizeof(participant::Vec3));
  return b.CreateVectorOfStructs(reinterpret_cast<const fb::Vec3*>(v.data()), v.size());
}

Offset<fb::SamplePoints> points(FlatBufferBuilder& b, const participant::SamplePoints& p) {
  return fb::CreateSamplePoints(b, vec3s(b, p.x), b.CreateVector(p.w), b.CreateVector(p.radius));
}

Offset<fb::SolveStats> stats(FlatBufferBuilder& b, const participant::SolveStats& s, double wall) {
  return fb::CreateSolveStats(b, s.converged, static_cast<std::uint32_t>(s.iterations), s.residual,
                              b.CreateVector(s.residual_history), b.CreateString(s.message), wall);
}

}  // namespace

Buffer hello(const Header& h, const std::string& software) {
  FlatBufferBuilder b;
  auto p = fb::CreateHello(b, h.sender, kProtocolVersion, b.CreateString(software));
  return finish(b, h, fb::Payload::Hello, p.Union());
}

Buffer hello_reply(const Header& h, const std::string& software, const participant::SamplePoints* pts) {
  FlatBufferBuilder b;
  auto sw = b.CreateString(software);
  Offset<fb::SamplePoints> sp = pts ? points(b, *pts) : Offset<fb::SamplePoints>();
  auto p = fb::CreateHelloReply(b, h.sender, kProtocolVersion, sw, sp);
  return finish(b, h, fb::Payload::HelloReply, p.Union());
}

Buffer step_begin(const Header& h, std::uint32_t step, double time, double dt) {
  FlatBufferBuilder b;
  auto p = fb::CreateStepBegin(b, step, time, dt);
  return finish(b, h, fb::Payload::StepBegin, p.Union());
}

Buffer beam_solve_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                          const std::vector<participant::Vec3>& line_loads, const participant::ContactPlanes* planes) {
  FlatBufferBuilder b(64 + 24 * line_loads.size() + (planes ? 56 * planes->size() : 0));
  const auto q = vec3s(b, line_loads);
  flatbuffers::Offset<flatbuffers::Vector<const fb::Vec3*>> s, n;
  flatbuffers::Offset<flatbuffers::Vector<double>> eps;
  if (planes) {
    s = vec3s(b, planes->s);
    n = vec3s(b, planes->n);
    eps = b.CreateVector(planes->eps);
  }
  auto p = fb::CreateBeamSolveRequest(b, step, iteration, q, s, n, eps, planes ? planes->g0 : 0.0);
  return finish(b, h, fb::Payload::BeamSolveRequest, p.Union());
}

Buffer beam_solve_reply(const Header& h, const participant::SolveStats& s, double wall,
                        const participant::SamplePoints& pts) {
  FlatBufferBuilder b(256 + 40 * pts.size());
  auto st = stats(b, s, wall);
  auto p = fb::CreateBeamSolveReply(b, st, points(b, pts));
  return finish(b, h, fb::Payload::BeamSolveReply, p.Union());
}

Buffer solid_solve_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                           const participant::SamplePoints& pts, double tolerance) {
  FlatBufferBuilder b(256 + 40 * pts.size());
  auto p = fb::CreateSolidSolveRequest(b, step, iteration, points(b, pts), tolerance);
  return finish(b, h, fb::Payload::SolidSolveRequest, p.Union());
}

Buffer solid_solve_reply(const Header& h, const participant::SolveStats& s, double wall,
                         const participant::ContactReply& c) {
  FlatBufferBuilder b(256 + 90 * c.line_loads.size());
  auto st = stats(b, s, wall);
  auto q = vec3s(b, c.line_loads);
  auto sp = vec3s(b, c.surface_points);
  auto n = vec3s(b, c.normals);
  auto eps = b.CreateVector(c.penalty);
  auto act = b.CreateVector(c.active);
  const fb::Vec3 f(c.total_force[0], c.total_force[1], c.total_force[2]);
  auto diag = fb::CreateContactDiagnostics(b, static_cast<std::uint32_t>(c.n_active), c.min_gap, &f);
  auto p = fb::CreateSolidSolveReply(b, st, q, sp, n, eps, act, diag, c.regularization);
  return finish(b, h, fb::Payload::SolidSolveReply, p.Union());
}

Buffer beam_linear_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                           const std::vector<double>& plane_shift, const std::vector<participant::Vec3>& normal_turn) {
  FlatBufferBuilder b(64 + 8 * plane_shift.size() + 24 * normal_turn.size());
  const auto shift = b.CreateVector(plane_shift);
  const auto turn = vec3s(b, normal_turn);
  auto p = fb::CreateBeamLinearRequest(b, step, iteration, shift, turn);
  return finish(b, h, fb::Payload::BeamLinearRequest, p.Union());
}

Buffer beam_linear_reply(const Header& h, const participant::SolveStats& s, double wall,
                         const std::vector<participant::Vec3>& dx) {
  FlatBufferBuilder b(256 + 24 * dx.size());
  auto st = stats(b, s, wall);
  auto p = fb::CreateBeamLinearReply(b, st, vec3s(b, dx));
  return finish(b, h, fb::Payload::BeamLinearReply, p.Union());
}

Buffer solid_linear_request(const Header& h, std::uint32_t step, std::uint32_t iteration,
                            const std::vector<participant::Vec3>& dx) {
  FlatBufferBuilder b(64 + 24 * dx.size());
  auto p = fb::CreateSolidLinearRequest(b, step, iteration, vec3s(b, dx));
  return finish(b, h, fb::Payload::SolidLinearRequest, p.Union());
}

Buffer solid_linear_reply(const Header& h, const participant::SolveStats& s, double wall,
                          const std::vector<double>& plane_shift, const std::vector<participant::Vec3>& normal_turn) {
  FlatBufferBuilder b(256 + 8 * plane_shift.size() + 24 * normal_turn.size());
  auto st = stats(b, s, wall);
  const auto shift = b.CreateVector(plane_shift);
  const auto turn = vec3s(b, normal_turn);
  auto p = fb::CreateSolidLinearReply(b, st, shift, turn);
  return finish(b, h, fb::Payload::SolidLinearReply, p.Union());
}

Buffer step_end(const Header& h, std::uint32_t step, bool accept) {
  FlatBufferBuilder b;
  auto p = fb::CreateStepEnd(b, step, accept);
  return finish(b, h, fb::Payload::StepEnd, p.Union());
}

Buffer ack(const Header& h) {
  FlatBufferBuilder b;
  auto p = fb::CreateAck(b);
  return finish(b, h, fb::Payload::Ack, p.Union());
}

Buffer shutdown(const Header& h, const std::string& reason) {
  FlatBufferBuilder b;
  auto p = fb::CreateShutdown(b, b.CreateString(reason));
  return finish(b, h, fb::Payload::Shutdown, p.Union());
}

Buffer error(const Header& h, const std::string& message, std::uint32_t step, std::uint32_t iteration,
             const std::vector<double>& history) {
  FlatBufferBuilder b;
  auto p = fb::CreateError(b, b.CreateString(message), step, iteration, b.CreateVector(history));
  return finish(b, h, fb::Payload::Error, p.Union());
}

}  // namespace angio::msg
