#pragma once
// A zenoh peer session: the entry point that opens the connection and declares everything else.
#include <chrono>
#include <functional>
#include <string>

#include "angio/transport/bytes.hpp"
#include "angio/transport/config.hpp"
#include "angio/transport/handle.hpp"
#include "angio/transport/liveliness.hpp"
#include "angio/transport/publisher.hpp"
#include "angio/transport/queryable.hpp"
#include "angio/transport/subscriber.hpp"

namespace angio::transport {

// Move-only. Destruction closes the session, ignoring errors; close() reports them.
class Session {
 public:
  // Throws TransportError if a listen endpoint cannot be bound or the config is invalid.
  static Session open(const SessionConfig& config);

  void close();
  bool is_open() const { return static_cast<bool>(handle_); }
  std::string zid() const;

  Queryable declare_queryable(const std::string& key) const;
  Publisher declare_publisher(const std::string& key) const;
  Subscriber declare_subscriber(const std::string& key) const;
  LivelinessToken declare_liveliness_token(const std::string& key) const;
  LivelinessWatcher watch_liveliness(const std::string& key) const;

  // Sends `payload` to the queryable on `key` and returns its reply. While no queryable is
  // reachable (peer not yet connected or declared) the request is re-sent every 20 ms, so
  // this also waits for a peer that is starting. Throws TimeoutError if no reply came within
  // `timeout`, RemoteError if the peer replied with an error, TransportError otherwise.
  // With `accept`, only a reply it takes counts; others (e.g. without the run's authentication
  // tag, from a foreign replier on the key) are skipped while the real one may still come.
  using Accept = std::function<bool(ByteView reply)>;
  Bytes request(const std::string& key, ByteView payload, std::chrono::milliseconds timeout,
                const Accept& accept = {}) const;

  // Single attempt: like request() but throws NoReplyError at once if no queryable answered.
  Bytes request_once(const std::string& key, ByteView payload, std::chrono::milliseconds timeout) const;

  // Asks the network whether a liveliness token matching `key` is alive (waits at most
  // `timeout` for answers; a missing peer simply yields false).
  bool liveliness_alive(const std::string& key, std::chrono::milliseconds timeout) const;

  az_session* raw() const noexcept { return handle_.get(); }

 private:
  explicit Session(az_session* s) : handle_(s) {}
  az_session* checked() const;
  detail::ShimHandle<az_session> handle_;
};

}  // namespace angio::transport
