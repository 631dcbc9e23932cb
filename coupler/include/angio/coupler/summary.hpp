// <run-dir>/coupling_summary.json of a coupled run (read by scripts/report.py, bench_scenes.py,
// stability.py and the scene tests): status ("ok" / "failed"), the error message of a failed run
// ("" otherwise), step and coupling-iteration counts, and the wall/solver/messaging seconds.
#pragma once

#include <string>

#include "angio/coupler/coupling_loop.hpp"

namespace angio::coupler {

// The summary as JSON text (nlohmann::json, indent 2, trailing newline; non-finite numbers as
// null, `error` escaped as any JSON string).
std::string coupling_summary_json(const std::string& status, const std::string& error, const RunReport& run,
                                  double messaging_time);

// Writes coupling_summary_json(...) to `path`; false when the file cannot be written (the
// caller logs it: a failed run must still report its own error first).
bool write_coupling_summary(const std::string& path, const std::string& status, const std::string& error,
                            const RunReport& run, double messaging_time);

}  // namespace angio::coupler
