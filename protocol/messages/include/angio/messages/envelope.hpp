// Opening and checking received envelopes (docs/design.md §4.2): every buffer is verified
// with the flatbuffers verifier before any field is read, then its identifier, protocol version,
// run id and sequence number are checked. Anything wrong is a ProtocolError with a clear message,
// never a crash.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "angio/fb/angio_generated.h"

namespace angio::msg {

// Bumped whenever the schema changes incompatibly.
inline constexpr std::uint32_t kProtocolVersion = 1;

class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Buffer = std::vector<std::uint8_t>;

const char* role_name(fb::Role r);  // "Coupler", "Beam", "Solid"
const char* role_key(fb::Role r);   // "coupler", "beam", "solid": the role in key expressions
const char* payload_name(fb::Payload p);

// The verb a request travels under (the last chunk of its key angio/<run>/<role>/<verb>): "hello",
// "step_begin", "solve", "step_end", "shutdown"; nullptr for payloads that are not requests.
const char* request_verb(fb::Payload p);
// Throws ProtocolError unless `key` ends in the verb of the envelope's payload: a request must not
// be answered under another verb (a foreign peer probing angio/<run>/<role>/anything).
void check_verb(const fb::Envelope& env, std::string_view key);

// Verifies `bytes` and returns the envelope inside (pointing into `bytes`). Throws ProtocolError
// for a truncated/corrupt buffer, a wrong file identifier, another protocol version or a foreign
// run id.
const fb::Envelope& open(std::span<const std::uint8_t> bytes, const std::string& run_id);

// Returns the payload of `env` as T, or throws ProtocolError naming what was expected and got.
template <class T>
const T& payload_as(const fb::Envelope& env) {
  const T* p = env.payload_as<T>();
  if (!p)
    throw ProtocolError(std::string("expected a ") + payload_name(fb::PayloadTraits<T>::enum_value) + " message, got " +
                        payload_name(env.payload_type()));
  return *p;
}

// Sequence bookkeeping of one conversation. A receiver of requests accepts only strictly
// increasing numbers within a window above the last one (a replayed or reordered request is
// rejected, and a forged number far ahead, e.g. 2^64 - 1, cannot lock the real requester out); a
// requester accepts only a reply carrying the number of the request it sent.
class Sequence {
 public:
  static constexpr std::uint64_t kWindow = 1000;  // the coupler numbers its requests consecutively
  std::uint64_t next() { return ++last_sent_; }
  void check_request(const fb::Envelope& env);
  void check_reply(const fb::Envelope& env, std::uint64_t request_sequence) const;

 private:
  std::uint64_t last_sent_ = 0;
  std::uint64_t last_received_ = 0;
};

}  // namespace angio::msg
