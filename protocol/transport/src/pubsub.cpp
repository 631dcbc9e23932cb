#include "angio/transport/publisher.hpp"
#include "angio/transport/subscriber.hpp"
#include "angio/transport/owned_buffer.hpp"
#include "ffi.hpp"

namespace angio::transport {

Publisher::Publisher(az_publisher* handle, std::string key) : handle_(handle), key_(std::move(key)) {}

void Publisher::put(ByteView data) const {
  detail::check(az_publisher_put(handle_.get(), data.data(), data.size()), "publish on", key_);
}

Subscriber::Subscriber(az_subscriber* handle, std::string key) : handle_(handle), key_(std::move(key)) {}

std::optional<Sample> Subscriber::recv(std::chrono::milliseconds timeout) const {
  az_bytes payload{nullptr, 0};
  az_bytes key{nullptr, 0};
  const int rc = az_subscriber_recv(handle_.get(), detail::to_ms(timeout), &payload, &key);
  OwnedBuffer p = OwnedBuffer::adopt(payload);
  OwnedBuffer k = OwnedBuffer::adopt(key);
  if (rc == AZ_TIMEOUT) return std::nullopt;
  detail::check(rc, "receive on subscriber", key_);
  return Sample{to_string(k.view()), p.to_vector()};
}

}  // namespace angio::transport
