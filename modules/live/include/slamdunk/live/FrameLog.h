#pragma once
// Every processed frame's record (status, reference keyframe, pose relative to it), appended
// by the tracking thread and read by the checkpoint writer while the session runs. A record
// costs the tracking thread one short lock; a reader copies only the records it has not seen.
// (SlamSystem keeps the same records, but for its own thread only.)

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
  size_t size() const;
  /// Appends the records from index `first` on to `out` (a reader's own copy).
  void copySince(size_t first, std::vector<FrameRecord>& out) const;

  /// The tracked frames' poses through their reference keyframes' poses in `graph` (a frame
  /// whose keyframe is not in the graph is left out, like a lost one).
  static Trajectory trajectory(const std::vector<FrameRecord>& records, const KeyframeGraph& graph);

 private:
  mutable std::mutex mutex_;
  std::deque<FrameRecord> records_;  ///< a deque: appending never moves what is stored
};

}  // namespace slamdunk::live
