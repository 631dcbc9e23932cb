// Minimal leveled logging shared by all executables: one concise line per load step at info,
// details at debug. Lines are prefixed with the process role so interleaved output stays readable.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace angio::log {

enum class Level { debug = 0, info = 1, warn = 2, error = 3 };

void set_role(const std::string& role);
void set_level(Level level);
Level level();
Level parse_level(const std::string& name);  // "debug", "info", "warn", "error"; throws otherwise
void write(Level level, const std::string& message);

inline bool enabled(Level l) { return static_cast<int>(l) >= static_cast<int>(level()); }

// "[a, b, c]": residual histories and similar lists in error reports.
std::string list(const std::vector<double>& values);

}  // namespace angio::log

// Streams only when the level is enabled: LOG_INFO("step " << n << " done");
#define ANGIO_LOG(lvl, expr)                         \
  do {                                               \
    if (::angio::log::enabled(lvl)) {                \
      std::ostringstream angio_log_os_;              \
      angio_log_os_ << expr;                         \
      ::angio::log::write(lvl, angio_log_os_.str()); \
    }                                                \
  } while (0)
#define LOG_DEBUG(expr) ANGIO_LOG(::angio::log::Level::debug, expr)
#define LOG_INFO(expr) ANGIO_LOG(::angio::log::Level::info, expr)
#define LOG_WARN(expr) ANGIO_LOG(::angio::log::Level::warn, expr)
#define LOG_ERROR(expr) ANGIO_LOG(::angio::log::Level::error, expr)
