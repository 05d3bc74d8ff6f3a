#pragma once
// The live threads: the grabber (opens the source, receives frames, optionally records them,
// hands them over latest-wins) and the tracker (SlamSystem::process on each frame, then the
// frame hook). The local optimization runs in SlamSystem's own thread, so tracking never waits
// for it. The caller's thread stays free for status output and signal handling. LiveSlam
// wires this to its outputs; use LiveSlam unless you need the threads alone.

#include <slamdunk/live/FrameSource.h>
#include <slamdunk/live/LatestFrameQueue.h>
#include <slamdunk/live/RawlogRecorder.h>

#include <slamdunk/slam/SlamSystem.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace slamdunk::live {

/// A consistent-enough picture of the counters (each one is exact; they are read one by one).
struct LiveCounters {
  /// processed = tracked + lost + frames skipped for a timestamp that did not increase
  size_t received = 0, processed = 0, dropped = 0, tracked = 0, lost = 0, keyframes = 0;
  TrackingStatus lastStatus = TrackingStatus::Lost;
  /// Localization only: tracked frames outside the mapped area, and whether the last one was.
  size_t outsideMap = 0;
  bool lastOutsideMap = false;
  double activeSeconds = 0;  ///< from the first frame received to the last one processed
  /// Where a delay came from when frames were dropped: the source (the longest time between
  /// two frames it handed over; a replay at 30 Hz: 33 ms) or the tracker (the longest time a
  /// processed frame waited in the queue).
  double longestSourceGapMs = 0, longestQueueWaitMs = 0;
};

class LivePipeline {
 public:
  /// Called on the tracking thread after each frame, with the frame, its result and its
  /// latency from grab to pose in ms. The next frame waits for it: keep it short.
  using FrameHook = std::function<void(const mrpt::obs::CObservation3DRangeScan&,
                                       const TrackingResult&, double latencyMs)>;

  /// recorder may be null; maxFrames = 0: no limit; hook may be empty.
  LivePipeline(FrameSource& source, SlamSystem& slam, size_t queueCapacity,
               RawlogRecorder* recorder, size_t maxFrames, FrameHook hook = {});
  ~LivePipeline();  ///< stops and joins
  LivePipeline(const LivePipeline&) = delete;
  LivePipeline& operator=(const LivePipeline&) = delete;

  void start();
  /// Waits until the source is open (true), it failed (throws its error), `timeoutSeconds`
  /// passed or `interrupted` became true (false).
  bool waitUntilOpen(double timeoutSeconds, const std::atomic<bool>& interrupted);
  /// The grabber stops; the tracker still processes the frames already handed over.
  void requestStop();
  bool finished() const { return trackingDone_; }
  void join();

  LiveCounters counters() const;
  /// The source's error that ended the run early (empty if it ended normally).
  std::string error() const;
  /// Per processed frame: milliseconds from its grab to its pose (queueing included).
  std::vector<double> latenciesMs() const;

 private:
  using Clock = std::chrono::steady_clock;
  void grabberLoop();
  void trackingLoop();

  FrameSource& source_;
  SlamSystem& slam_;
  RawlogRecorder* recorder_;
  const size_t maxFrames_;
  FrameHook hook_;
  LatestFrameQueue queue_;

  std::atomic<bool> stop_{false}, trackingDone_{false};
  std::atomic<size_t> received_{0}, processed_{0}, tracked_{0}, lost_{0}, keyframes_{0};
  std::atomic<int> lastStatus_{static_cast<int>(TrackingStatus::Lost)};
  std::atomic<size_t> outsideMap_{0};
  std::atomic<bool> lastOutsideMap_{false};
  std::atomic<Clock::rep> firstFrame_{0}, lastProcessed_{0};           ///< Clock ticks, 0 = not yet
  std::atomic<Clock::rep> longestSourceGap_{0}, longestQueueWait_{0};  ///< Clock ticks

  enum class OpenState { Pending, Open, Failed };
  mutable std::mutex mutex_;  // guards openState_, error_, latenciesMs_
  std::condition_variable openChanged_;
  OpenState openState_ = OpenState::Pending;
  std::string error_;
  SessionLog<double> latenciesMs_;  ///< one per frame, for as long as the session runs

  std::thread grabber_, tracker_;
};

}  // namespace slamdunk::live
