#pragma once
// Fire-and-forget publication, used for human-readable status lines.
#include <memory>
#include <string>
#include <string_view>

#include "angio/transport/bytes.hpp"

struct az_publisher;

namespace angio::transport {

class Publisher {
 public:
  Publisher(az_publisher* handle, std::string key);
  Publisher(Publisher&&) noexcept = default;
  Publisher& operator=(Publisher&&) noexcept = default;

  const std::string& key() const { return key_; }
  void put(ByteView data) const;
  void put(std::string_view text) const { put(as_bytes(text)); }

 private:
  struct Dropper {
    void operator()(az_publisher* p) const noexcept;
  };
  std::unique_ptr<az_publisher, Dropper> handle_;
  std::string key_;
};

}  // namespace angio::transport
