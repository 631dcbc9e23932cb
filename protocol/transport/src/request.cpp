// Session::request / request_once: the requesting side of request/reply.
#include <algorithm>
#include <optional>
#include <thread>

#include "angio/transport/errors.hpp"
#include "angio/transport/owned_buffer.hpp"
#include "angio/transport/session.hpp"
#include "ffi.hpp"

namespace angio::transport {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// How long to wait before re-sending a request that found no queryable: short enough that a
// peer coming up is noticed quickly, long enough not to spin on a loaded machine.
constexpr milliseconds no_route_backoff{20};

std::string timeout_message(const std::string& key, milliseconds timeout, bool route_seen) {
  return "request to '" + key + "' got no reply within " + std::to_string(timeout.count()) + " ms (" +
         (route_seen ? "the queryable did not answer in time" : "no queryable reachable on this key") + ")";
}

// The C callback in front of Session::Accept: exceptions must not cross into Rust.
int accept_trampoline(void* ctx, const std::uint8_t* data, std::size_t len) {
  try {
    return (*static_cast<const Session::Accept*>(ctx))(ByteView(data, len)) ? 1 : 0;
  } catch (...) {
    return 0;
  }
}

// One az_request call waiting at most `wait`: the reply, or nullopt when the request finished
// without any (no queryable reachable). Throws TimeoutError naming the caller's `timeout` when
// the queryable did not answer in time, RemoteError / TransportError on failures.
std::optional<Bytes> attempt(az_session* s, const std::string& key, ByteView payload, milliseconds wait,
                             milliseconds timeout, const Session::Accept& accept = {}) {
  az_bytes raw{nullptr, 0};
  const int rc =
      az_request(s, key.c_str(), payload.data(), payload.size(), detail::to_ms(wait),
                 accept ? accept_trampoline : nullptr, accept ? const_cast<Session::Accept*>(&accept) : nullptr, &raw);
  const OwnedBuffer reply = OwnedBuffer::adopt(raw);
  switch (rc) {
    case AZ_OK:
      return reply.to_vector();
    case AZ_TIMEOUT:
      throw TimeoutError(timeout_message(key, timeout, true));
    case AZ_NO_REPLY:
      return std::nullopt;
    default:
      detail::throw_status(rc, "request to '" + key + "'");
  }
}

}  // namespace

Bytes Session::request_once(const std::string& key, ByteView payload, milliseconds timeout) const {
  if (auto reply = attempt(checked(), key, payload, timeout, timeout)) return std::move(*reply);
  throw NoReplyError("request to '" + key + "' finished without reply (no queryable reachable)");
}

Bytes Session::request(const std::string& key, ByteView payload, milliseconds timeout, const Accept& accept) const {
  const auto deadline = Clock::now() + detail::clamp_timeout(timeout);
  for (;;) {
    const auto remaining = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (remaining <= milliseconds::zero()) throw TimeoutError(timeout_message(key, timeout, false));
    if (auto reply = attempt(checked(), key, payload, remaining, timeout, accept)) return std::move(*reply);
    // No queryable known yet (peer still connecting or not started): try again.
    std::this_thread::sleep_for(std::min(no_route_backoff, remaining));
  }
}

}  // namespace angio::transport
