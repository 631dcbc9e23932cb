// Helper process for the two-process tests. Opens a session (listening or connecting),
// holds a liveliness token, and answers requests on a key until it receives "shutdown":
//   reply = "echo:" + request payload, or "bye" to "shutdown" (then exits 0).
//
//   transport_test_server (--listen EP | --connect EP) --key K --token T [--max-seconds S]
#include <chrono>
#include <cstring>
#include <iostream>
#include <string>

#include "angio/transport.hpp"

namespace at = angio::transport;
using namespace std::chrono;

int main(int argc, char** argv) {
  at::SessionConfig config;
  std::string key;
  std::string token_key;
  int max_seconds = 120;  // never outlive a broken test run
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const std::string value = argv[i + 1];
    if (flag == "--listen")
      config.listen.push_back(value);
    else if (flag == "--connect")
      config.connect.push_back(value);
    else if (flag == "--key")
      key = value;
    else if (flag == "--token")
      token_key = value;
    else if (flag == "--max-seconds")
      max_seconds = std::stoi(value);
    else {
      std::cerr << "unknown flag " << flag << "\n";
      return 2;
    }
  }
  if (key.empty() || token_key.empty()) {
    std::cerr << "--key and --token are required\n";
    return 2;
  }
  try {
    auto session = at::Session::open(config);
    auto queryable = session.declare_queryable(key);
    auto token = session.declare_liveliness_token(token_key);
    const auto give_up = steady_clock::now() + seconds(max_seconds);
    bool shutdown = false;
    queryable.serve(
        [&](const at::IncomingQuery& q) {
          const std::string request = at::to_string(q.payload());
          if (request == "shutdown") {
            shutdown = true;
            return at::Bytes{'b', 'y', 'e'};
          }
          at::Bytes reply{'e', 'c', 'h', 'o', ':'};
          reply.insert(reply.end(), q.payload().begin(), q.payload().end());
          return reply;
        },
        [&] { return shutdown || steady_clock::now() > give_up; });
    if (!shutdown) {
      std::cerr << "transport_test_server: no shutdown request within " << max_seconds << " s\n";
      return 3;
    }
    // Explicit close so a close error fails the test; zenoh's graceful close still delivers
    // the already queued "bye" reply.
    session.close();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "transport_test_server: " << e.what() << "\n";
    return 1;
  }
}
