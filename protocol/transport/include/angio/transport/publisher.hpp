#pragma once
// Fire-and-forget publication, used for human-readable status lines.
#include <string>
#include <string_view>

#include "angio/transport/bytes.hpp"
#include "angio/transport/handle.hpp"

namespace angio::transport {

class Publisher {
 public:
  Publisher(az_publisher* handle, std::string key);

  const std::string& key() const { return key_; }
  void put(ByteView data) const;
  void put(std::string_view text) const { put(as_bytes(text)); }

 private:
  detail::ShimHandle<az_publisher> handle_;
  std::string key_;
};

}  // namespace angio::transport
