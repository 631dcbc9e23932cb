#pragma once
// What a session listens on / connects to. Endpoints are zenoh locators such as
// "tcp/127.0.0.1:7447" or "unixsock-stream//run/dir/angio.sock".
#include <filesystem>
#include <string>
#include <vector>

namespace angio::transport {

struct SessionConfig {
  std::vector<std::string> listen;  // must be bindable when the session opens
  // Retried in the background until the peer listens; Session::open waits at most 0.5 s
  // for a first connection, so it never blocks on an absent peer.
  std::vector<std::string> connect;
};

// Unix-socket endpoint inside a run directory, for runs whose processes share one host.
// Throws TransportError if the resulting socket path exceeds the OS limit (107 bytes).
std::string default_endpoint_for(const std::filesystem::path& run_dir);

}  // namespace angio::transport
