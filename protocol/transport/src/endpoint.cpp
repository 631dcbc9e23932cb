#include <string>

#include "angio/transport/config.hpp"
#include "angio/transport/errors.hpp"

namespace angio::transport {

std::string default_endpoint_for(const std::filesystem::path& run_dir) {
  // sockaddr_un::sun_path holds 108 bytes including the terminating NUL.
  constexpr std::size_t max_socket_path = 107;
  const std::string path = (std::filesystem::absolute(run_dir) / "angio.sock").lexically_normal().string();
  if (path.size() > max_socket_path) {
    throw TransportError("unix socket path too long (" + std::to_string(path.size()) + " > 107 bytes): " + path +
                         "; use a shorter run directory or tcp");
  }
  return "unixsock-stream/" + path;
}

}  // namespace angio::transport
