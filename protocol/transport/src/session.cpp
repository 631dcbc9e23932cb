#include "angio/transport/session.hpp"

#include <array>
#include <vector>

#include "angio/transport/errors.hpp"
#include "ffi.hpp"

namespace angio::transport {

namespace {

std::vector<const char*> c_strings(const std::vector<std::string>& v) {
  std::vector<const char*> out;
  out.reserve(v.size());
  for (const auto& s : v) out.push_back(s.c_str());
  return out;
}

std::string describe(const SessionConfig& c) {
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& e : v) s += (s.empty() ? "" : ",") + e;
    return "[" + s + "]";
  };
  return "listen " + join(c.listen) + ", connect " + join(c.connect);
}

// Shared body of the declare_* functions whose shim call takes (session, key, out).
template <class Entity, class Raw>
Entity declare(az_session* s, const std::string& key, int (*shim_declare)(const az_session*, const char*, Raw**),
               std::string_view what) {
  Raw* handle = nullptr;
  detail::check(shim_declare(s, key.c_str(), &handle), what, key);
  return Entity(handle, key);
}

}  // namespace

Session Session::open(const SessionConfig& config) {
  const auto listen = c_strings(config.listen);
  const auto connect = c_strings(config.connect);
  az_session* s = nullptr;
  detail::check(az_session_open(listen.data(), listen.size(), connect.data(), connect.size(), &s),
                "cannot open transport session (" + describe(config) + ")");
  return Session(s);
}

az_session* Session::checked() const {
  if (!handle_) throw TransportError("transport session is closed");
  return handle_.get();
}

void Session::close() {
  if (!handle_) return;
  detail::check(az_session_close(handle_.release()), "error closing transport session");
}

std::string Session::zid() const {
  std::array<char, 64> buf{};
  detail::check(az_session_zid(checked(), buf.data(), buf.size()), "cannot read session id");
  return std::string(buf.data());
}

Queryable Session::declare_queryable(const std::string& key) const {
  return declare<Queryable>(checked(), key, az_queryable_declare, "declare_queryable");
}

Publisher Session::declare_publisher(const std::string& key) const {
  return declare<Publisher>(checked(), key, az_publisher_declare, "declare_publisher");
}

Subscriber Session::declare_subscriber(const std::string& key) const {
  return declare<Subscriber>(checked(), key, az_subscriber_declare, "declare_subscriber");
}

LivelinessToken Session::declare_liveliness_token(const std::string& key) const {
  return declare<LivelinessToken>(checked(), key, az_liveliness_token_declare, "declare_liveliness_token");
}

LivelinessWatcher Session::watch_liveliness(const std::string& key) const {
  az_liveliness_subscriber* s = nullptr;
  detail::check(az_liveliness_subscriber_declare(checked(), key.c_str(), /*history=*/1, &s), "watch_liveliness", key);
  return LivelinessWatcher(s, key);
}

bool Session::liveliness_alive(const std::string& key, std::chrono::milliseconds timeout) const {
  std::size_t count = 0;
  detail::check(az_liveliness_count(checked(), key.c_str(), detail::to_ms(timeout), &count), "liveliness query", key);
  return count > 0;
}

}  // namespace angio::transport
