#include "angio/messages/envelope.hpp"

namespace angio::msg {

const char* role_name(fb::Role r) { return fb::EnumNameRole(r); }

const char* role_key(fb::Role r) {
  switch (r) {
    case fb::Role::Beam:
      return "beam";
    case fb::Role::Solid:
      return "solid";
    default:
      return "coupler";
  }
}

const char* payload_name(fb::Payload p) {
  const char* n = fb::EnumNamePayload(p);
  return (n && *n) ? n : "unknown payload";
}

const char* request_verb(fb::Payload p) {
  switch (p) {
    case fb::Payload::Hello:
      return "hello";
    case fb::Payload::StepBegin:
      return "step_begin";
    case fb::Payload::BeamSolveRequest:
    case fb::Payload::SolidSolveRequest:
      return "solve";
    case fb::Payload::BeamLinearRequest:
    case fb::Payload::SolidLinearRequest:
      return "linearize";
    case fb::Payload::StepEnd:
      return "step_end";
    case fb::Payload::Shutdown:
      return "shutdown";
    default:
      return nullptr;
  }
}

void check_verb(const fb::Envelope& env, std::string_view key) {
  const auto slash = key.rfind('/');
  const std::string_view verb = slash == std::string_view::npos ? key : key.substr(slash + 1);
  const char* expected = request_verb(env.payload_type());
  if (!expected) throw ProtocolError(std::string("a ") + payload_name(env.payload_type()) + " is not a request");
  if (verb != expected)
    throw ProtocolError("a " + std::string(payload_name(env.payload_type())) + " request under the verb '" +
                        std::string(verb) + "' (expected '" + expected + "')");
}

const fb::Envelope& open(std::span<const std::uint8_t> bytes, const std::string& run_id) {
  if (bytes.size() < 8)
    throw ProtocolError("message of " + std::to_string(bytes.size()) + " bytes is too short to be an angio envelope");
  if (!flatbuffers::BufferHasIdentifier(bytes.data(), fb::EnvelopeIdentifier()))
    throw ProtocolError("message does not carry the angio file identifier 'ANGI' (foreign data)");
  flatbuffers::Verifier verifier(bytes.data(), bytes.size());
  if (!fb::VerifyEnvelopeBuffer(verifier))
    throw ProtocolError("message of " + std::to_string(bytes.size()) +
                        " bytes failed flatbuffers verification (truncated or corrupt)");
  const fb::Envelope* env = fb::GetEnvelope(bytes.data());
  if (env->protocol_version() != kProtocolVersion)
    throw ProtocolError("message has protocol version " + std::to_string(env->protocol_version()) +
                        ", this build speaks version " + std::to_string(kProtocolVersion));
  const std::string got = env->run_id() ? env->run_id()->str() : std::string();
  if (got != run_id)
    throw ProtocolError("message belongs to run '" + got + "', this process serves run '" + run_id + "'");
  if (env->payload_type() == fb::Payload::NONE || !env->payload()) throw ProtocolError("message has no payload");
  return *env;
}

void Sequence::check_request(const fb::Envelope& env) {
  if (env.sequence() <= last_received_ || env.sequence() - last_received_ > kWindow)
    throw ProtocolError("out-of-sequence " + std::string(payload_name(env.payload_type())) + ": number " +
                        std::to_string(env.sequence()) + " after " + std::to_string(last_received_) +
                        " (expected one of the next " + std::to_string(kWindow) + ")");
  last_received_ = env.sequence();
}

void Sequence::check_reply(const fb::Envelope& env, std::uint64_t request_sequence) const {
  if (env.sequence() != request_sequence)
    throw ProtocolError("reply " + std::string(payload_name(env.payload_type())) + " carries number " +
                        std::to_string(env.sequence()) + ", expected " + std::to_string(request_sequence));
}

}  // namespace angio::msg
