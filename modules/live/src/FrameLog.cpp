#include <slamdunk/live/FrameLog.h>

namespace slamdunk::live {

void FrameLog::append(const FrameRecord& record) {
  std::lock_guard lock(mutex_);
  pending_.push_back(record);
}

void FrameLog::takeNew(std::deque<FrameRecord>& out) {
  std::vector<FrameRecord> taken;
  {
    std::lock_guard lock(mutex_);
    taken.swap(pending_);
  }
  out.insert(out.end(), taken.begin(), taken.end());
}

Trajectory FrameLog::trajectory(const std::deque<FrameRecord>& records,
                                const KeyframeGraph& graph) {
  const auto poses = graph.poses();
  Trajectory out;
  out.reserve(records.size());
  for (const FrameRecord& f : records) {
    if (f.status == TrackingStatus::Lost) continue;
    const auto it = poses.find(f.reference);
    if (it != poses.end()) out.push_back({f.timestamp, it->second * f.poseInReference});
  }
  return out;
}

}  // namespace slamdunk::live
