#include "angio/common/log.hpp"

#include <cstdio>
#include <mutex>
#include <stdexcept>

namespace angio::log {
namespace {
std::string g_role = "angio";
Level g_level = Level::info;
std::mutex g_mutex;
const char* name(Level l) {
  switch (l) {
    case Level::debug:
      return "debug";
    case Level::info:
      return "info";
    case Level::warn:
      return "WARN";
    case Level::error:
      return "ERROR";
  }
  return "?";
}
}  // namespace

void set_role(const std::string& role) { g_role = role; }
void set_level(Level level) { g_level = level; }
Level level() { return g_level; }

Level parse_level(const std::string& n) {
  if (n == "debug") return Level::debug;
  if (n == "info") return Level::info;
  if (n == "warn") return Level::warn;
  if (n == "error") return Level::error;
  throw std::invalid_argument("log level '" + n + "': expected debug, info, warn or error");
}

void write(Level level, const std::string& message) {
  std::lock_guard<std::mutex> lock(g_mutex);
  FILE* out = level >= Level::warn ? stderr : stdout;
  if (level == Level::info)
    std::fprintf(out, "[%s] %s\n", g_role.c_str(), message.c_str());
  else
    std::fprintf(out, "[%s] %s: %s\n", g_role.c_str(), name(level), message.c_str());
  std::fflush(out);
}

std::string list(const std::vector<double>& values) {
  std::ostringstream os;
  os << "[";
  for (std::size_t i = 0; i < values.size(); ++i) os << (i ? ", " : "") << values[i];
  return os.str() + "]";
}

}  // namespace angio::log
