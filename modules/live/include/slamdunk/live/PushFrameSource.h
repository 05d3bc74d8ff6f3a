#pragma once
// Frames handed over by the application itself (its own driver, a ROS callback, a simulator):
// push() from any thread never blocks, and the pipeline's grabber thread takes the frames from
// here. close() ends the stream, like a camera unplugged at the end of a session.

#include <slamdunk/live/FrameSource.h>
#include <slamdunk/live/LatestFrameQueue.h>

#include <mutex>

namespace slamdunk::live {

class PushFrameSource : public FrameSource {
 public:
  /// At most `capacity` pushed frames wait for the grabber thread (it takes each at once, so
  /// this only fills when the whole process is starved); beyond that the oldest is dropped.
  explicit PushFrameSource(size_t capacity = 8);

  /// Queues a frame; its images must be in memory or loadable (loaded on the grabber
  /// thread: loadExternalImages). Returns false (the frame is ignored) once close() was called.
  bool push(mrpt::obs::CObservation3DRangeScan::Ptr frame);
  /// No more frames: the pipeline processes those already pushed, then ends.
  void close();
  /// Frames dropped here because the grabber thread did not keep up.
  size_t dropped() const { return queue_.dropped(); }

  void open() override {}
  /// Waits for a pushed frame; nullptr once closed and drained, or when `stop` is set.
  mrpt::obs::CObservation3DRangeScan::Ptr next(const std::atomic<bool>& stop) override;
  std::string describe() const override { return "frames pushed by the application"; }

 private:
  LatestFrameQueue queue_;
  std::mutex closeMutex_;  // a push either lands before close() or is refused
  bool closed_ = false;
};

}  // namespace slamdunk::live
