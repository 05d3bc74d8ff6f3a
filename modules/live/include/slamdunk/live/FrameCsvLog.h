#pragma once
// One CSV line per processed frame (LiveSession::frameLog, slamdunk-live --frame-log): when it was
// grabbed, its latency from grab to pose, the tracking time, the tracking state and the keyframe
// count. Long sessions (soak tests) read memory and latency trends from it. Streamed to a temporary
// file by the tracking thread and renamed over the target by finish(), like every other output.

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/tracking/Tracker.h>

#include <chrono>
#include <fstream>
#include <optional>

namespace slamdunk::live {

class FrameCsvLog {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;

  /// Opens the temporary file; throws std::runtime_error if it cannot be created.
  explicit FrameCsvLog(const std::string& path);

  /// From the tracking thread, once per processed frame.
  void add(const TrackingResult& r, TimePoint grabbed, double latencyMs, size_t keyframes);
  /// Closes the file and renames it over the target; throws on a write error.
  void finish();

 private:
  AtomicOutput output_;
  std::ofstream file_;
  size_t index_ = 0;
  std::optional<TimePoint> firstGrab_;
};

}  // namespace slamdunk::live
