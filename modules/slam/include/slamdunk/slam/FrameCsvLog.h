#pragma once
// The frame log of slamdunk-rawlog and slamdunk-live (--frame-log): one CSV line per processed
// frame, the same columns offline and live (FrameCsvLog::kHeader). What the tracker measured
// (features, matches, inliers, overlap, keyframe, loop closure, ms per stage, position, why a
// frame was lost) and, for live frames only, when the frame was grabbed and its latency from
// grab to pose (empty offline). Long sessions (soak tests) read memory and latency trends from
// it, scripts/keyframe-policy-report.py what the keyframe policy saw.
//
// The tracking thread only formats its line into memory: a thread of the log's own writes the
// lines out about once a second, because a write can wait on the disk (hundreds of ms while
// another process flushes) and the tracker must not.

#include <slamdunk/tracking/Tracker.h>

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace slamdunk {

class FrameCsvLog {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  /// The columns, in order; the last one (free text) has its commas replaced by ';'.
  static const char* const kHeader;

  /// When a live frame was grabbed, and how long it took from there to its pose.
  struct Grab {
    TimePoint grabbed;
    double latencyMs = 0;
  };

  /// Creates `path` (the caller stages it: AtomicOutput, StagedOutputs) and starts the writer;
  /// throws std::runtime_error if it cannot be created.
  explicit FrameCsvLog(const std::string& path);
  ~FrameCsvLog();  ///< without finish(): stops the writer, the file stays incomplete
  FrameCsvLog(const FrameCsvLog&) = delete;
  FrameCsvLog& operator=(const FrameCsvLog&) = delete;

  /// From the tracking thread, once per processed frame: formats the line, never writes.
  void add(const TrackingResult& r, const std::optional<Grab>& grab = std::nullopt);
  /// Writes what is left and closes the file; throws std::runtime_error on a write error.
  void finish();

 private:
  void writerLoop();
  void stopWriter();

  std::ofstream file_;
  size_t index_ = 0, keyframes_ = 0;  // tracking thread only
  std::optional<TimePoint> firstGrab_;

  std::mutex mutex_;  // guards pending_, stopping_
  std::condition_variable wake_;
  std::string pending_;  ///< lines formatted, not yet written
  bool stopping_ = false;
  std::thread writer_;
};

}  // namespace slamdunk
