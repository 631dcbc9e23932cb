#include "ffi.hpp"

#include "angio/transport/errors.hpp"

namespace angio::transport::detail {

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
