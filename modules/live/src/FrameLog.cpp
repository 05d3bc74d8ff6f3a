#include <slamdunk/live/FrameLog.h>

namespace slamdunk::live {

void FrameLog::append(const FrameRecord& record) {
  std::lock_guard lock(mutex_);
  pending_.push_back(record);
}

void FrameLog::revise(const std::vector<TrackingResult::RevisedFrame>& revised) {
  if (revised.empty()) return;
  std::lock_guard lock(mutex_);
  revisions_.insert(revisions_.end(), revised.begin(), revised.end());
}

void FrameLog::takeNew(SessionLog<FrameRecord>& out) {
  // Two vectors swapped back and forth keep their capacity: no buffer of a checkpoint
  // interval's records is allocated and freed each time.
  {
    std::lock_guard lock(mutex_);
    spare_.swap(pending_);
    spareRevisions_.swap(revisions_);
  }
  out.append(spare_.begin(), spare_.end());
  spare_.clear();
  reviseFrameRecords(out, spareRevisions_);
  spareRevisions_.clear();
}

}  // namespace slamdunk::live
