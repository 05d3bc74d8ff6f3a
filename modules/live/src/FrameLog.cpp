#include <slamdunk/live/FrameLog.h>

namespace slamdunk::live {

void FrameLog::append(const FrameRecord& record) {
  std::lock_guard lock(mutex_);
  records_.push_back(record);
}

size_t FrameLog::size() const {
  std::lock_guard lock(mutex_);
  return records_.size();
}

void FrameLog::copySince(size_t first, std::vector<FrameRecord>& out) const {
  std::lock_guard lock(mutex_);
  if (first >= records_.size()) return;
  out.insert(out.end(), records_.begin() + static_cast<std::ptrdiff_t>(first), records_.end());
}

Trajectory FrameLog::trajectory(const std::vector<FrameRecord>& records,
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
