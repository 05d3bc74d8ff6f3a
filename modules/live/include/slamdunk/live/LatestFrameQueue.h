#pragma once
// The hand-off between the grabber and the tracker. A camera cannot be paused, so when tracking
// falls behind the OLDEST waiting frame is dropped (and counted): the tracker always works on
// the most recent frames and the delay between capture and pose stays bounded.

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>

namespace slamdunk::live {

class LatestFrameQueue {
 public:
  using FramePtr = mrpt::obs::CObservation3DRangeScan::Ptr;
  using TimePoint = std::chrono::steady_clock::time_point;

  /// capacity >= 1 frames may wait; 1 = strictly the latest frame.
  explicit LatestFrameQueue(size_t capacity);

  /// Never blocks. Returns true if the oldest waiting frame had to be dropped to make room.
  /// `grabbed`: when the frame was received, for its latency from grab to pose.
  bool push(FramePtr frame, TimePoint grabbed = std::chrono::steady_clock::now());
  /// Blocks until a frame is waiting (returns it, and when it was grabbed if asked) or the
  /// queue is closed and empty (nullptr).
  FramePtr pop(TimePoint* grabbed = nullptr);
  /// As pop(), but also returns nullptr once `stop` is set (set without the queue's lock, so
  /// it is looked at every 50 ms).
  FramePtr pop(const std::atomic<bool>& stop);
  /// No more frames will come: pop() returns what is left, then nullptr.
  void close();
  size_t dropped() const;

 private:
  /// The oldest waiting frame, nullptr when none; the caller holds mutex_.
  FramePtr takeOldest(TimePoint* grabbed);

  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::pair<FramePtr, TimePoint>> frames_;
  size_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace slamdunk::live
