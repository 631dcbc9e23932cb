// Peer authentication (docs/reliability.md "Security"; docs/design.md §4.5): every message of a coupled run travels
// sealed with an HMAC-SHA256 tag under the run's secret key, so only processes that can read the run's key file
// (owner-only, in the owner-only run directory) can speak for the coupler or a participant. A
// foreign peer on the run's endpoint, even one that knows the run id and the key expressions,
// cannot forge a request or a reply. The tag covers the whole envelope (run id, sender, sequence
// number, payload), so a captured message cannot be altered, and it cannot be replayed either: the
// sequence checks (msg::Sequence) refuse a number already seen.
//
// Wire format: envelope bytes || 32-byte tag; the tag is HMAC-SHA256(key, "angio-seal-1" || envelope)
// (RFC 2104, OpenSSL's implementation). Recordings keep the envelopes without tags, so they do not
// depend on the key of the run that wrote them.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace angio::msg {

// The key file is missing, unreadable, readable by others or not 64 hex digits: bad input (exit 2).
class KeyFileError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class RunKey {
 public:
  static constexpr std::size_t kKeyBytes = 32;
  static constexpr std::size_t kTagBytes = 32;

  explicit RunKey(const std::array<std::uint8_t, kKeyBytes>& secret) : secret_(secret) {}
  // Reads a key file: one line of 64 hex digits, owned by this user, not accessible to group or
  // others (like ssh's private keys). Throws KeyFileError naming the file and what was expected.
  static RunKey read(const std::filesystem::path& file);

  // envelope || tag
  std::vector<std::uint8_t> seal(std::span<const std::uint8_t> envelope) const;
  // The envelope inside `sealed`; throws ProtocolError when the tag is missing or does not match
  // (a message from a process without the run's key, or altered on the way).
  std::span<const std::uint8_t> unseal(std::span<const std::uint8_t> sealed) const;
  // The envelope inside `sealed` if its tag is valid, else nullopt (the filter for replies,
  // transport::Session::Accept, which then keeps the envelope: each reply is checked once).
  std::optional<std::span<const std::uint8_t>> verified(std::span<const std::uint8_t> sealed) const noexcept;

 private:
  std::array<std::uint8_t, kTagBytes> tag_(std::span<const std::uint8_t> envelope) const;
  std::array<std::uint8_t, kKeyBytes> secret_;
};

}  // namespace angio::msg
