#pragma once
// Every processed frame's record (status, reference keyframe, pose relative to it), handed from
// the tracking thread to the checkpoint writer. A record costs the tracking thread one short
// lock; the writer takes the records appended since its last checkpoint and keeps the only
// copy of them (SlamSystem keeps its own, for its own thread): the log itself holds one
// checkpoint interval's records at most, so a long session keeps each record twice, not three
// times (a 30-minute soak: 57.6 MB an hour with the third copy, 44.6 without).

#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/slam/SlamSystem.h>

#include <deque>
#include <mutex>
#include <vector>

namespace slamdunk::live {

class FrameLog {
 public:
  void append(const FrameRecord& record);
  /// Moves the records appended since the last call to the end of `out` (the reader's copy).
  void takeNew(std::deque<FrameRecord>& out);

  /// The tracked frames' poses through their reference keyframes' poses in `graph` (a frame
  /// whose keyframe is not in the graph is left out, like a lost one).
  static Trajectory trajectory(const std::deque<FrameRecord>& records, const KeyframeGraph& graph);

 private:
  std::mutex mutex_;
  std::vector<FrameRecord> pending_;  ///< appended since the last takeNew()
};

}  // namespace slamdunk::live
