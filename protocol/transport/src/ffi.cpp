#include "ffi.hpp"

#include "angio/transport/errors.hpp"
#include "angio/transport/handle.hpp"

namespace angio::transport::detail {

void ShimRelease::operator()(az_session* s) const noexcept { az_session_close(s); }
void ShimRelease::operator()(az_queryable* q) const noexcept { az_queryable_drop(q); }
void ShimRelease::operator()(az_query* q) const noexcept { az_query_drop(q); }
void ShimRelease::operator()(az_publisher* p) const noexcept { az_publisher_drop(p); }
void ShimRelease::operator()(az_subscriber* s) const noexcept { az_subscriber_drop(s); }
void ShimRelease::operator()(az_token* t) const noexcept { az_liveliness_token_drop(t); }
void ShimRelease::operator()(az_liveliness_subscriber* s) const noexcept { az_liveliness_subscriber_drop(s); }

std::string last_error() {
  const char* msg = az_last_error();
  return msg ? std::string(msg) : std::string();
}

void throw_status(int rc, std::string_view context) {
  std::string what = std::string(context) + ": " + last_error();
  switch (rc) {
    case AZ_ERR_REPLY:
      throw RemoteError(what);
    case AZ_ERR_PANIC:
      throw TransportError(what + " (internal error in the zenoh shim)");
    default:
      throw TransportError(what);
  }
}

}  // namespace angio::transport::detail
