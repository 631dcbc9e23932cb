#pragma once
// Receives publications on a key expression (wildcards allowed), queued until recv.
#include <chrono>
#include <optional>
#include <string>

#include "angio/transport/bytes.hpp"
#include "angio/transport/handle.hpp"

namespace angio::transport {

struct Sample {
  std::string key;
  Bytes payload;
  std::string text() const { return to_string(payload); }
};

class Subscriber {
 public:
  Subscriber(az_subscriber* handle, std::string key);

  const std::string& key() const { return key_; }
  // Next sample, or nullopt if none arrived within `timeout`.
  std::optional<Sample> recv(std::chrono::milliseconds timeout) const;

 private:
  detail::ShimHandle<az_subscriber> handle_;
  std::string key_;
};

}  // namespace angio::transport
