// zenoh key expressions of a run (docs/design.md §4.3): angio/<run_id>/<role>/<verb> for
// requests, angio/<run_id>/alive/<role> for liveliness tokens, angio/<run_id>/status for status
// lines.
#pragma once

#include <string>

namespace angio::participant::keys {

inline std::string request(const std::string& run, const std::string& role, const std::string& verb) {
  return "angio/" + run + "/" + role + "/" + verb;
}
inline std::string serve(const std::string& run, const std::string& role) { return "angio/" + run + "/" + role + "/*"; }
inline std::string alive(const std::string& run, const std::string& role) { return "angio/" + run + "/alive/" + role; }
inline std::string status(const std::string& run) { return "angio/" + run + "/status"; }

}  // namespace angio::participant::keys
