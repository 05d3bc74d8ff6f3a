#pragma once
// Pause and single-step for an offline run shown in the viewer: the processing loop calls
// waitForTurn() before each frame; keys in the window call togglePause() and step(). The run
// stays deterministic: pausing only delays frames, it never skips or reorders them.

#include <condition_variable>
#include <mutex>

namespace slamdunk::viewer {

class PlaybackControl {
 public:
  void togglePause();
  /// While paused: lets exactly one more frame through. Running: pauses after the next frame.
  void step();
  /// Never blocks again (the window was closed, or the run is ending).
  void release();
  bool paused() const;

  /// Returns at once unless paused; while paused, waits for step() (returns: one frame),
  /// togglePause() or release().
  void waitForTurn();
  /// How many threads are blocked in waitForTurn() now (counted only while they really wait;
  /// one that may go at once is never counted): tests wait for a frame to be held.
  size_t waiting() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool paused_ = false, released_ = false;
  size_t steps_ = 0;    ///< frames allowed through while paused
  size_t waiting_ = 0;  ///< threads blocked in waitForTurn()
};

}  // namespace slamdunk::viewer
