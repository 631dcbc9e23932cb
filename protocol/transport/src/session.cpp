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

}  // namespace

void Session::Closer::operator()(az_session* s) const noexcept { az_session_close(s); }

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
  az_queryable* q = nullptr;
  detail::check(az_queryable_declare(checked(), key.c_str(), &q), "declare_queryable '" + key + "'");
  return Queryable(q, key);
}

Publisher Session::declare_publisher(const std::string& key) const {
  az_publisher* p = nullptr;
  detail::check(az_publisher_declare(checked(), key.c_str(), &p), "declare_publisher '" + key + "'");
  return Publisher(p, key);
}

Subscriber Session::declare_subscriber(const std::string& key) const {
  az_subscriber* s = nullptr;
  detail::check(az_subscriber_declare(checked(), key.c_str(), &s), "declare_subscriber '" + key + "'");
  return Subscriber(s, key);
}

LivelinessToken Session::declare_liveliness_token(const std::string& key) const {
  az_token* t = nullptr;
  detail::check(az_liveliness_token_declare(checked(), key.c_str(), &t),
                "declare_liveliness_token '" + key + "'");
  return LivelinessToken(t, key);
}

LivelinessWatcher Session::watch_liveliness(const std::string& key) const {
  az_liveliness_subscriber* s = nullptr;
  detail::check(az_liveliness_subscriber_declare(checked(), key.c_str(), /*history=*/1, &s),
                "watch_liveliness '" + key + "'");
  return LivelinessWatcher(s, key);
}

bool Session::liveliness_alive(const std::string& key, std::chrono::milliseconds timeout) const {
  std::size_t count = 0;
  detail::check(az_liveliness_count(checked(), key.c_str(), detail::to_ms(timeout), &count),
                "liveliness query '" + key + "'");
  return count > 0;
}

}  // namespace angio::transport
