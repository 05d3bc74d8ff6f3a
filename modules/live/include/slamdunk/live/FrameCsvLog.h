#pragma once
// One CSV line per processed frame (LiveSession::frameLog, slamdunk-live --frame-log): when it was
// grabbed, its latency from grab to pose, the tracking time, the tracking state and the keyframe
// count. Long sessions (soak tests) read memory and latency trends from it. The tracking thread
// only formats its line into memory: a thread of the log's own writes the lines out about once
// a second, because a write can wait on the disk (hundreds of ms while another process flushes)
// and the tracker must not. The file is streamed to a temporary name and renamed over the
// target by finish(), like every other output.

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/tracking/Tracker.h>

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace slamdunk::live {

class FrameCsvLog {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;

  /// Opens the temporary file and starts the writer; throws std::runtime_error if the file
  /// cannot be created.
  explicit FrameCsvLog(const std::string& path);
  ~FrameCsvLog();  ///< without finish(): stops the writer and removes the temporary file
  FrameCsvLog(const FrameCsvLog&) = delete;
  FrameCsvLog& operator=(const FrameCsvLog&) = delete;

  /// From the tracking thread, once per processed frame: formats the line, never writes.
  void add(const TrackingResult& r, TimePoint grabbed, double latencyMs, size_t keyframes);
  /// Writes what is left, closes the file and renames it over the target; throws on a write
  /// error.
  void finish();

 private:
  void writerLoop();
  void stopWriter();

  AtomicOutput output_;
  std::ofstream file_;
  size_t index_ = 0;  // tracking thread only
  std::optional<TimePoint> firstGrab_;

  std::mutex mutex_;  // guards pending_, stopping_
  std::condition_variable wake_;
  std::string pending_;  ///< lines formatted, not yet written
  bool stopping_ = false;
  std::thread writer_;
};

}  // namespace slamdunk::live
