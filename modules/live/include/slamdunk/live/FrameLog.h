#pragma once
// Every processed frame's record (status, reference keyframe, pose relative to it), handed from
// the tracking thread to the checkpoint writer. A record costs the tracking thread one short
// lock; the writer takes the records appended since its last checkpoint and keeps the only
// copy of them (SlamSystem keeps its own, for its own thread): the log itself holds one
// checkpoint interval's records at most. Both copies are SessionLogs, whose older entries live
// in a temporary file: a long session's memory does not grow with its frames.

#include <slamdunk/slam/SlamSystem.h>

#include <mutex>
#include <vector>

namespace slamdunk::live {

class FrameLog {
 public:
  void append(const FrameRecord& record);
  /// New poses for frames already appended (TrackingResult::revisedFrames), applied to the
  /// reader's copy at the next takeNew() (reviseFrameRecords).
  void revise(const std::vector<TrackingResult::RevisedFrame>& revised);
  /// Moves the records appended since the last call to the end of `out` (the reader's copy),
  /// and applies the revisions.
  void takeNew(SessionLog<FrameRecord>& out);

 private:
  std::mutex mutex_;
  std::vector<FrameRecord> pending_;  ///< appended since the last takeNew()
  std::vector<FrameRecord> spare_;    ///< the reader's side of the swap, its capacity kept
  std::vector<TrackingResult::RevisedFrame> revisions_, spareRevisions_;  ///< likewise
};

}  // namespace slamdunk::live
