// Wall-clock timing for logs and reports (steady clock, seconds as double).
#pragma once

#include <chrono>

namespace angio {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace angio
