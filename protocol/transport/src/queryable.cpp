#include "angio/transport/queryable.hpp"

#include <exception>

#include "angio/transport/errors.hpp"
#include "ffi.hpp"

namespace angio::transport {

IncomingQuery::IncomingQuery(az_query* handle, OwnedBuffer payload) : handle_(handle), payload_(std::move(payload)) {}

std::string_view IncomingQuery::key() const {
  const char* k = handle_ ? az_query_keyexpr(handle_.get()) : nullptr;
  return k ? std::string_view(k) : std::string_view();
}

// az_query_reply / az_query_reply_err free the handle whatever the outcome, so the key is gone
// by the time a failure is reported; the shim's message names it.
void IncomingQuery::reply(ByteView data) {
  if (!handle_) throw TransportError("query was already answered");
  detail::check(az_query_reply(handle_.release(), data.data(), data.size()), "reply");
}

void IncomingQuery::reply_error(std::string_view message) {
  if (!handle_) throw TransportError("query was already answered");
  const ByteView bytes = as_bytes(message);
  detail::check(az_query_reply_err(handle_.release(), bytes.data(), bytes.size()), "error reply");
}

Queryable::Queryable(az_queryable* handle, std::string key) : handle_(handle), key_(std::move(key)) {}

std::optional<IncomingQuery> Queryable::recv(std::chrono::milliseconds timeout) const {
  az_query* q = nullptr;
  az_bytes payload{nullptr, 0};
  const int rc = az_queryable_recv(handle_.get(), detail::to_ms(timeout), &q, &payload);
  if (rc == AZ_TIMEOUT) return std::nullopt;
  detail::check(rc, "receive on queryable", key_);
  return IncomingQuery(q, OwnedBuffer::adopt(payload));
}

std::size_t Queryable::serve(const Handler& handler, const std::function<bool()>& should_stop,
                             std::chrono::milliseconds poll) const {
  std::size_t answered = 0;
  while (!(should_stop && should_stop())) {
    auto query = recv(poll);
    if (!query) continue;
    try {
      Bytes out = handler(*query);
      query->reply(out);
    } catch (const std::exception& e) {
      // The requester gets a RemoteError with this text instead of waiting for its timeout.
      if (!query->answered()) query->reply_error(e.what());
    }
    ++answered;
  }
  return answered;
}

}  // namespace angio::transport
