#pragma once
// Peer presence: a process holds a LivelinessToken for as long as it is up; the other side
// watches the token's key and learns when it disappears (clean exit, crash or kill alike).
#include <chrono>
#include <optional>
#include <set>
#include <string>

#include "angio/transport/handle.hpp"

namespace angio::transport {

class LivelinessToken {
 public:
  LivelinessToken(az_token* handle, std::string key);

  const std::string& key() const { return key_; }

 private:
  detail::ShimHandle<az_token> handle_;
  std::string key_;
};

struct LivelinessEvent {
  std::string key;
  bool alive;  // true: token appeared; false: token disappeared
};

// Tracks which tokens matching a key expression are alive (tokens alive at creation included).
class LivelinessWatcher {
 public:
  LivelinessWatcher(az_liveliness_subscriber* handle, std::string key);

  const std::string& key() const { return key_; }

  // Next change (also applied to alive_keys()), or nullopt if none within `timeout`.
  std::optional<LivelinessEvent> recv(std::chrono::milliseconds timeout);

  // Waits until at least one / no matching token is alive; false if `timeout` elapsed first.
  bool wait_until_alive(std::chrono::milliseconds timeout);
  bool wait_until_gone(std::chrono::milliseconds timeout);

  // State as of the events received so far (call recv or a wait_* to refresh).
  bool any_alive() const { return !alive_.empty(); }
  const std::set<std::string>& alive_keys() const { return alive_; }

 private:
  detail::ShimHandle<az_liveliness_subscriber> handle_;
  std::string key_;
  std::set<std::string> alive_;
};

}  // namespace angio::transport
