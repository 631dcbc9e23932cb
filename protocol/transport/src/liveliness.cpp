#include "angio/transport/liveliness.hpp"

#include "angio/transport/owned_buffer.hpp"
#include "ffi.hpp"

namespace angio::transport {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

LivelinessToken::LivelinessToken(az_token* handle, std::string key) : handle_(handle), key_(std::move(key)) {}

LivelinessWatcher::LivelinessWatcher(az_liveliness_subscriber* handle, std::string key)
    : handle_(handle), key_(std::move(key)) {}

std::optional<LivelinessEvent> LivelinessWatcher::recv(milliseconds timeout) {
  int alive = 0;
  az_bytes key{nullptr, 0};
  const int rc = az_liveliness_subscriber_recv(handle_.get(), detail::to_ms(timeout), &alive, &key);
  OwnedBuffer k = OwnedBuffer::adopt(key);
  if (rc == AZ_TIMEOUT) return std::nullopt;
  detail::check(rc, "liveliness watch on", key_);
  LivelinessEvent ev{to_string(k.view()), alive != 0};
  if (ev.alive) {
    alive_.insert(ev.key);
  } else {
    alive_.erase(ev.key);
  }
  return ev;
}

namespace {

template <class Done>
bool wait_for(LivelinessWatcher& w, milliseconds timeout, Done done) {
  const auto deadline = Clock::now() + detail::clamp_timeout(timeout);
  // Apply changes already queued first, so a stale state is never taken as the answer.
  while (w.recv(milliseconds::zero())) {
  }
  while (!done()) {
    const auto remaining = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (remaining <= milliseconds::zero()) return false;
    w.recv(remaining);
  }
  return true;
}

}  // namespace

bool LivelinessWatcher::wait_until_alive(milliseconds timeout) {
  return wait_for(*this, timeout, [this] { return any_alive(); });
}

bool LivelinessWatcher::wait_until_gone(milliseconds timeout) {
  return wait_for(*this, timeout, [this] { return !any_alive(); });
}

}  // namespace angio::transport
