#pragma once
// Serving side of request/reply: a queryable on one key expression whose incoming queries
// are pulled one by one (recv) or handled in a loop (serve).
#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "angio/transport/bytes.hpp"
#include "angio/transport/handle.hpp"
#include "angio/transport/owned_buffer.hpp"

namespace angio::transport {

// One received request. Reply exactly once. If it is destroyed unanswered the requester sees
// "no reply", which Session::request cannot tell from "no queryable yet" and so re-sends the
// request until its timeout: always answer, with reply_error if need be. Move-only.
class IncomingQuery {
 public:
  IncomingQuery(az_query* handle, OwnedBuffer payload);

  std::string_view key() const;  // empty once answered
  ByteView payload() const { return payload_.view(); }
  bool answered() const { return !handle_; }

  void reply(ByteView data);
  void reply_error(std::string_view message);

 private:
  detail::ShimHandle<az_query> handle_;
  OwnedBuffer payload_;
};

class Queryable {
 public:
  // Returns the reply payload; an exception is sent back as an error reply (RemoteError).
  using Handler = std::function<Bytes(const IncomingQuery&)>;

  Queryable(az_queryable* handle, std::string key);

  const std::string& key() const { return key_; }

  // Next query, or nullopt if none arrived within `timeout`. Throws TransportError if the
  // session was closed.
  std::optional<IncomingQuery> recv(std::chrono::milliseconds timeout) const;

  // Answers queries with `handler` until `should_stop()` returns true (checked after every
  // query and at least every `poll`). Returns the number of queries answered.
  std::size_t serve(const Handler& handler, const std::function<bool()>& should_stop,
                    std::chrono::milliseconds poll = std::chrono::milliseconds(100)) const;

 private:
  detail::ShimHandle<az_queryable> handle_;
  std::string key_;
};

}  // namespace angio::transport
