#pragma once
// Private glue between the C ABI status codes and the C++ exceptions.
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "angio_zenoh.h"

namespace angio::transport::detail {

std::string last_error();

// Throws the exception matching `rc` (< 0) with `context` and the shim's message.
[[noreturn]] void throw_status(int rc, std::string_view context);

inline void check(int rc, std::string_view context) {
  if (rc < 0) throw_status(rc, context);
}

// Same with the context "<what> '<key>'", only built on failure: calls made for every message
// (put, recv) allocate no error text when they succeed.
inline void check(int rc, std::string_view what, std::string_view key) {
  if (rc < 0) throw_status(rc, std::string(what) + " '" + std::string(key) + "'");
}

// Same bound as the shim applies: "forever"-style values (milliseconds::max()) must not
// overflow deadline arithmetic.
inline std::chrono::milliseconds clamp_timeout(std::chrono::milliseconds d) {
  constexpr std::chrono::milliseconds max_timeout = std::chrono::hours(24 * 30);
  return d < std::chrono::milliseconds::zero() ? std::chrono::milliseconds::zero()
                                               : (d > max_timeout ? max_timeout : d);
}

inline std::uint64_t to_ms(std::chrono::milliseconds d) { return static_cast<std::uint64_t>(clamp_timeout(d).count()); }

}  // namespace angio::transport::detail
