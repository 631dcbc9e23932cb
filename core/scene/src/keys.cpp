#include "angio/scene/keys.hpp"

#include <algorithm>
#include <regex>
#include <sstream>

namespace angio::scene::keys {

namespace {
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  if (s.empty()) return out;
  std::stringstream ss(s);
  for (std::string part; std::getline(ss, part, sep);) out.push_back(part);
  return out;
}

std::vector<std::string> segments_of(const std::string& path) {
  static const std::regex index(R"(\[[0-9]+\])");
  return split(std::regex_replace(path, index, "[]"), '.');
}

bool segment_matches(const std::string& pattern, const std::string& s) {
  const bool list = s.size() >= 2 && s.compare(s.size() - 2, 2, "[]") == 0;
  return pattern == s || (pattern == "*" && !list);
}

// Whether the first segments of `pattern` match `segs`; the wildcards used, or -1.
int match_prefix(const std::vector<std::string>& pattern, const std::vector<std::string>& segs) {
  if (pattern.size() < segs.size()) return -1;
  int wild = 0;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    if (!segment_matches(pattern[i], segs[i])) return -1;
    wild += pattern[i] == "*";
  }
  return wild;
}
}  // namespace

const Decl* find(const std::string& path) {
  const auto segs = segments_of(path);
  const Decl* best = nullptr;
  int best_wild = 0;
  for (const Decl& d : kTable) {
    const auto pattern = split(d.path, '.');
    if (pattern.size() != segs.size()) continue;
    const int wild = match_prefix(pattern, segs);
    if (wild >= 0 && (!best || wild < best_wild)) best = &d, best_wild = wild;
  }
  return best;
}

std::vector<std::string> children(const std::string& path) {
  const auto segs = segments_of(path);
  std::vector<std::string> out;
  for (const Decl& d : kTable) {
    const auto pattern = split(d.path, '.');
    if (pattern.size() != segs.size() + 1 || match_prefix(pattern, segs) < 0) continue;
    std::string name = pattern.back();
    if (name.size() >= 2 && name.compare(name.size() - 2, 2, "[]") == 0) name.resize(name.size() - 2);
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  return out;
}

bool has_type(const Decl& d, const std::string& t) {
  const auto types = split(d.type, '|');
  return std::find(types.begin(), types.end(), t) != types.end();
}

bool allows(const Decl& d, const std::string& v) {
  const auto values = split(d.values, '|');
  return values.empty() || std::find(values.begin(), values.end(), v) != values.end();
}

}  // namespace angio::scene::keys
