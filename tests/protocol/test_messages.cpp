// Message round trips and rejection of malformed, foreign and old messages.
#include <gtest/gtest.h>

#include <cmath>

#include "angio/messages/builders.hpp"
#include "angio/messages/convert.hpp"
#include "angio/messages/step_state.hpp"

using namespace angio;
using angio::msg::ProtocolError;

namespace {
msg::Header coupler(std::uint64_t seq) { return {"run-A", seq, fb::Role::Coupler}; }

participant::SamplePoints points(std::size_t n) {
  participant::SamplePoints p;
  for (std::size_t i = 0; i < n; ++i) {
    p.x.push_back({0.1 * i, -1.0 * i, 2.5});
    p.w.push_back(0.01 + i);
    p.radius.push_back(0.06);
  }
  return p;
}
}  // namespace

TEST(Messages, BeamSolveRequestRoundTrip) {
  std::vector<participant::Vec3> q = {{1, 2, 3}, {-4, 5.5, 1e-9}};
  auto buf = msg::beam_solve_request(coupler(7), 3, 2, q);
  const auto& env = msg::open(buf, "run-A");
  EXPECT_EQ(env.sequence(), 7u);
  EXPECT_EQ(env.sender(), fb::Role::Coupler);
  const auto& r = msg::payload_as<fb::BeamSolveRequest>(env);
  EXPECT_EQ(r.step(), 3u);
  EXPECT_EQ(r.iteration(), 2u);
  EXPECT_EQ(msg::to_vec3s(r.line_loads()), q);
}

// The interface Newton–Krylov's requests and replies carry their vectors unchanged.
TEST(Messages, LinearResponsesRoundTrip) {
  const std::vector<double> shift = {0.5, -1e-7, 0.0};
  const std::vector<participant::Vec3> turn = {{0, 0.1, 0}, {1e-9, 0, -2}, {0, 0, 0}};
  const auto& beam = msg::payload_as<fb::BeamLinearRequest>(
      msg::open(msg::beam_linear_request(coupler(3), 4, 1, shift, turn), "run-A"));
  EXPECT_EQ(beam.step(), 4u);
  EXPECT_EQ(msg::to_doubles(beam.plane_shift()), shift);
  EXPECT_EQ(msg::to_vec3s(beam.normal_turn()), turn);
  participant::SolveStats st;
  st.converged = true;
  const auto& solid = msg::payload_as<fb::SolidLinearReply>(
      msg::open(msg::solid_linear_reply(coupler(4), st, 0.01, shift, turn), "run-A"));
  EXPECT_TRUE(msg::to_stats(solid.stats()).converged);
  EXPECT_EQ(msg::to_doubles(solid.plane_shift()), shift);
  EXPECT_EQ(msg::to_vec3s(solid.normal_turn()), turn);
  EXPECT_STREQ(msg::request_verb(fb::Payload::BeamLinearRequest), "linearize");
  EXPECT_STREQ(msg::request_verb(fb::Payload::SolidLinearRequest), "linearize");
}

TEST(Messages, SolidSolveRoundTrip) {
  auto pts = points(5);
  auto req = msg::solid_solve_request(coupler(1), 1, 0, pts, 2.5e-3);
  const auto& r = msg::payload_as<fb::SolidSolveRequest>(msg::open(req, "run-A"));
  EXPECT_EQ(r.tolerance(), 2.5e-3);
  auto back = msg::to_sample_points(r.sample_points());
  EXPECT_EQ(back.x, pts.x);
  EXPECT_EQ(back.w, pts.w);
  EXPECT_EQ(back.radius, pts.radius);

  participant::ContactReply c;
  c.line_loads = {{0, 0, -1}, {0, 1, 0}};
  c.surface_points = {{1, 1, 1}};
  c.normals = {{0, 0, 1}};
  c.penalty = {10.0};
  c.active = {1, 0};
  c.n_active = 1;
  c.min_gap = -1e-3;
  c.total_force = {0.5, 0, -2};
  participant::SolveStats s{true, 4, 1e-10, {1, 1e-3, 1e-10}, ""};
  auto rep = msg::solid_solve_reply({"run-A", 1, fb::Role::Solid}, s, 0.25, c);
  const auto& env = msg::open(rep, "run-A");
  const auto& sr = msg::payload_as<fb::SolidSolveReply>(env);
  auto c2 = msg::to_contact(sr);
  EXPECT_EQ(c2.line_loads, c.line_loads);
  EXPECT_EQ(c2.active, c.active);
  EXPECT_EQ(c2.n_active, 1);
  EXPECT_DOUBLE_EQ(c2.min_gap, -1e-3);
  EXPECT_EQ(c2.total_force, c.total_force);
  auto s2 = msg::to_stats(sr.stats());
  EXPECT_TRUE(s2.converged);
  EXPECT_EQ(s2.residual_history, s.residual_history);
  EXPECT_DOUBLE_EQ(sr.stats()->wall_time(), 0.25);
}

TEST(Messages, HelloAndControlMessages) {
  auto pts = points(3);
  auto h = msg::hello_reply({"run-A", 1, fb::Role::Beam}, "beam_solver 0.1", &pts);
  const auto& hr = msg::payload_as<fb::HelloReply>(msg::open(h, "run-A"));
  EXPECT_EQ(hr.role(), fb::Role::Beam);
  EXPECT_EQ(hr.protocol_version(), msg::kProtocolVersion);
  EXPECT_EQ(msg::to_sample_points(hr.sample_points()).size(), 3u);

  const auto& se = msg::payload_as<fb::StepEnd>(msg::open(msg::step_end(coupler(2), 9, false), "run-A"));
  EXPECT_EQ(se.step(), 9u);
  EXPECT_FALSE(se.accept());
  const auto& sd = msg::payload_as<fb::Shutdown>(msg::open(msg::shutdown(coupler(3), "done"), "run-A"));
  EXPECT_EQ(sd.reason()->str(), "done");
  const auto& er =
      msg::payload_as<fb::Error>(msg::open(msg::error(coupler(4), "no convergence", 5, 2, {1.0, 0.5}), "run-A"));
  EXPECT_EQ(er.message()->str(), "no convergence");
  EXPECT_EQ(er.residual_history()->size(), 2u);
}

TEST(Messages, WrongPayloadTypeIsAClearError) {
  auto buf = msg::step_begin(coupler(1), 1, 0.02, 0.02);
  const auto& env = msg::open(buf, "run-A");
  try {
    msg::payload_as<fb::BeamSolveRequest>(env);
    FAIL() << "no exception";
  } catch (const ProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("expected a BeamSolveRequest message, got StepBegin"), std::string::npos)
        << e.what();
  }
}

TEST(Messages, RejectsForeignRun) {
  auto buf = msg::ack({"run-B", 1, fb::Role::Solid});
  EXPECT_THROW(msg::open(buf, "run-A"), ProtocolError);
}

TEST(Messages, RejectsTruncatedAndCorruptBuffers) {
  auto buf = msg::beam_solve_request(coupler(1), 1, 0, std::vector<participant::Vec3>(100));
  // Every truncation must be rejected without touching memory outside the buffer.
  for (std::size_t n : {std::size_t{0}, std::size_t{4}, std::size_t{12}, buf.size() / 2, buf.size() - 1}) {
    std::vector<std::uint8_t> cut(buf.begin(), buf.begin() + n);
    EXPECT_THROW(msg::open(cut, "run-A"), ProtocolError) << "length " << n;
  }
  // Flipping bytes of the root offset makes the verifier fail.
  auto bad = buf;
  bad[0] ^= 0xFF;
  bad[1] ^= 0xFF;
  EXPECT_THROW(msg::open(bad, "run-A"), ProtocolError);
}

TEST(Messages, RejectsWrongIdentifier) {
  auto buf = msg::ack(coupler(1));
  buf[4] = 'X';  // file identifier sits at bytes 4..7
  try {
    msg::open(buf, "run-A");
    FAIL();
  } catch (const ProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("identifier"), std::string::npos);
  }
}

TEST(Messages, RejectsOtherProtocolVersion) {
  flatbuffers::FlatBufferBuilder b;
  auto p = fb::CreateAck(b);
  auto env = fb::CreateEnvelope(b, msg::kProtocolVersion + 1, b.CreateString("run-A"), 1, fb::Role::Beam,
                                fb::Payload::Ack, p.Union());
  fb::FinishEnvelopeBuffer(b, env);
  std::vector<std::uint8_t> buf(b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize());
  try {
    msg::open(buf, "run-A");
    FAIL();
  } catch (const ProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("protocol version"), std::string::npos);
  }
}

TEST(Messages, SequenceChecks) {
  msg::Sequence seq;
  auto a = msg::ack(coupler(5));
  auto b = msg::ack(coupler(5));
  auto c = msg::ack(coupler(4));
  auto d = msg::ack(coupler(6));
  seq.check_request(msg::open(a, "run-A"));
  EXPECT_THROW(seq.check_request(msg::open(b, "run-A")), ProtocolError);  // replayed
  EXPECT_THROW(seq.check_request(msg::open(c, "run-A")), ProtocolError);  // reordered
  seq.check_request(msg::open(d, "run-A"));
  EXPECT_NO_THROW(seq.check_reply(msg::open(d, "run-A"), 6));
  EXPECT_THROW(seq.check_reply(msg::open(d, "run-A"), 7), ProtocolError);
  // a forged number far ahead is refused and does not lock the real requester out
  auto forged = msg::ack(coupler(~std::uint64_t{0}));
  EXPECT_THROW(seq.check_request(msg::open(forged, "run-A")), ProtocolError);
  auto e = msg::ack(coupler(7));
  EXPECT_NO_THROW(seq.check_request(msg::open(e, "run-A")));
  auto gap = msg::ack(coupler(7 + msg::Sequence::kWindow));  // a gap within the window
  EXPECT_NO_THROW(seq.check_request(msg::open(gap, "run-A")));
}

TEST(Messages, MismatchedSamplePointArraysAreRejected) {
  auto pts = points(4);
  pts.w.pop_back();
  auto buf = msg::solid_solve_request(coupler(1), 1, 0, pts, 0.0);
  const auto& r = msg::payload_as<fb::SolidSolveRequest>(msg::open(buf, "run-A"));
  EXPECT_THROW(msg::to_sample_points(r.sample_points()), ProtocolError);
}

// The step protocol a participant accepts (msg::StepState): the regular order passes (a rejected
// step begun again included); out of order, a non-finite time, or a request for another step is
// refused and leaves the state unchanged, as is a solid solve request with a NaN or negative
// tolerance (robustness against stray or forged requests).
TEST(Messages, StepStateAcceptsTheProtocolOrderOnly) {
  using angio::msg::StepState;
  std::uint64_t n = 0;
  auto ok = [&](StepState& s, const msg::Buffer& b) { s.check(msg::open(b, "run-A")); };
  auto refused = [&](StepState& s, const msg::Buffer& b, const std::string& what) {
    try {
      s.check(msg::open(b, "run-A"));
      ADD_FAILURE() << "accepted: " << what;
    } catch (const ProtocolError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  participant::SamplePoints pts;
  StepState s;
  refused(s, msg::step_begin(coupler(++n), 1, 0.1, 0.1), "before Hello");
  ok(s, msg::hello(coupler(++n), "test"));
  refused(s, msg::step_end(coupler(++n), 1, true), "outside a step");
  refused(s, msg::solid_solve_request(coupler(++n), 1, 0, pts, 0.0), "outside a step");
  refused(s, msg::beam_linear_request(coupler(++n), 1, 0, {}, {}), "outside a step");
  refused(s, msg::solid_linear_request(coupler(++n), 1, 0, {}), "outside a step");
  refused(s, msg::step_begin(coupler(++n), 1, std::nan(""), 0.1), "expected finite values");
  refused(s, msg::step_begin(coupler(++n), 1, 0.1, -0.1), "increment >= 0");
  EXPECT_FALSE(s.in_step());
  ok(s, msg::step_begin(coupler(++n), 1, 0.1, 0.1));
  refused(s, msg::step_begin(coupler(++n), 2, 0.2, 0.1), "while step 1 is open");
  refused(s, msg::beam_solve_request(coupler(++n), 2, 0, {}), "while step 1 is open");
  ok(s, msg::beam_solve_request(coupler(++n), 1, 0, {}));
  ok(s, msg::solid_solve_request(coupler(++n), 1, 1, pts, 0.0));
  ok(s, msg::beam_linear_request(coupler(++n), 1, 1, {}, {}));
  ok(s, msg::solid_linear_request(coupler(++n), 1, 1, {}));
  refused(s, msg::solid_linear_request(coupler(++n), 2, 1, {}), "while step 1 is open");
  refused(s, msg::solid_solve_request(coupler(++n), 1, 2, pts, std::nan("")), "expected a finite value >= 0");
  refused(s, msg::solid_solve_request(coupler(++n), 1, 2, pts, -1e-3), "expected a finite value >= 0");
  refused(s, msg::step_end(coupler(++n), 2, false), "while step 1 is open");
  ok(s, msg::step_end(coupler(++n), 1, false));  // rejected: the same step begins again, halved
  ok(s, msg::step_begin(coupler(++n), 1, 0.05, 0.05));
  ok(s, msg::step_end(coupler(++n), 1, true));
  EXPECT_FALSE(s.in_step());
  ok(s, msg::shutdown(coupler(++n), "done"));
}

// A request is answered only under its own verb (angio/<run>/<role>/<verb>): a foreign peer querying
// another verb, or a reply sent as a request, is refused.
TEST(Messages, RequestsTravelUnderTheirOwnVerb) {
  std::uint64_t n = 0;
  const auto hello = msg::hello(coupler(++n), "test");
  const auto end = msg::step_end(coupler(++n), 1, true);
  EXPECT_NO_THROW(msg::check_verb(msg::open(hello, "run-A"), "angio/run-A/solid/hello"));
  EXPECT_NO_THROW(msg::check_verb(msg::open(end, "run-A"), "angio/run-A/beam/step_end"));
  try {
    msg::check_verb(msg::open(hello, "run-A"), "angio/run-A/solid/solve");
    ADD_FAILURE() << "a Hello under 'solve' accepted";
  } catch (const ProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("under the verb 'solve' (expected 'hello')"), std::string::npos) << e.what();
  }
  EXPECT_THROW(msg::check_verb(msg::open(msg::ack(coupler(++n)), "run-A"), "angio/run-A/solid/ack"), ProtocolError);
  EXPECT_STREQ(msg::request_verb(fb::Payload::SolidSolveRequest), "solve");
  EXPECT_EQ(msg::request_verb(fb::Payload::Error), nullptr);
}
