#pragma once
// Byte-span helpers so callers can pass strings and typed buffers without casts.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace angio::transport {

using Bytes = std::vector<std::uint8_t>;
using ByteView = std::span<const std::uint8_t>;

inline ByteView as_bytes(std::string_view s) { return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}; }

inline std::string to_string(ByteView b) { return {reinterpret_cast<const char*>(b.data()), b.size()}; }

}  // namespace angio::transport
