#pragma once
// Timing of a piece of work for the reports, on the steady clock (a wall-clock change during a
// run must not show as a slow frame).

#include <chrono>

namespace slamdunk {

using SteadyClock = std::chrono::steady_clock;

/// Milliseconds from t to now.
inline double msSince(SteadyClock::time_point t) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - t).count();
}

}  // namespace slamdunk
