#pragma once
// Receives publications on a key expression (wildcards allowed), queued until recv.
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "angio/transport/bytes.hpp"

struct az_subscriber;

namespace angio::transport {

struct Sample {
  std::string key;
  Bytes payload;
  std::string text() const { return to_string(payload); }
};

class Subscriber {
 public:
  Subscriber(az_subscriber* handle, std::string key);
  Subscriber(Subscriber&&) noexcept = default;
  Subscriber& operator=(Subscriber&&) noexcept = default;

  const std::string& key() const { return key_; }
  // Next sample, or nullopt if none arrived within `timeout`.
  std::optional<Sample> recv(std::chrono::milliseconds timeout) const;

 private:
  struct Dropper {
    void operator()(az_subscriber* s) const noexcept;
  };
  std::unique_ptr<az_subscriber, Dropper> handle_;
  std::string key_;
};

}  // namespace angio::transport
