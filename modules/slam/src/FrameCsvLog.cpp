#include <slamdunk/core/WorkerThread.h>
#include <slamdunk/slam/FrameCsvLog.h>

#include <cstdio>
#include <stdexcept>

namespace slamdunk {

const char* const FrameCsvLog::kHeader =
    "index,timestamp,status,features,matches,inliers,overlap,new_keyframe,keyframe_id,"
    "loop_closure,reference,ms_features,ms_pool,ms_matching,ms_ransac,ms_total,tx,ty,tz,"
    "pool_size,depth_only,ms_pool_wait,relocalized,overlap_cells,keyframes,loop_corrected,"
    "outside_map,grab_s,latency_ms,lost_reason";

FrameCsvLog::FrameCsvLog(const std::string& path) : file_(path) {
  if (!file_) throw std::runtime_error("cannot create it");
  file_ << kHeader << '\n';
  writer_ = std::thread([this] { writerLoop(); });
}

FrameCsvLog::~FrameCsvLog() { stopWriter(); }

void FrameCsvLog::add(const TrackingResult& r, const std::optional<Grab>& grab) {
  if (r.newKeyframe) ++keyframes_;
  keyframes_ -= r.culledKeyframes.size();
  const Eigen::Vector3d t = r.pose.translation();
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%zu,%.6f,%s,%zu,%zu,%zu,%.3f,%d,%u,%d,%u,%.3f,%.3f,%.3f,%.3f,%.3f,%.5f,%.5f,%.5f,"
                "%zu,%d,%.3f,%d,%d,%zu,%d,%d,",
                index_++, r.timestamp, r.skipped ? "skipped" : toString(r.status), r.features,
                r.matches, r.inliers, r.overlap, r.newKeyframe ? 1 : 0, r.keyframeId,
                r.loopClosure ? 1 : 0, r.reference, r.timings.features, r.timings.pool,
                r.timings.matching, r.timings.ransac, r.timings.total, t.x(), t.y(), t.z(),
                r.poolSize, r.depthOnly ? 1 : 0, r.timings.poolWait, r.relocalized ? 1 : 0,
                r.overlapCells, keyframes_, r.loopCorrected ? 1 : 0, r.outsideMap ? 1 : 0);
  std::string line = buf;
  if (grab) {
    if (!firstGrab_) firstGrab_ = grab->grabbed;
    const double grabSeconds = std::chrono::duration<double>(grab->grabbed - *firstGrab_).count();
    std::snprintf(buf, sizeof buf, "%.3f,%.3f,", grabSeconds, grab->latencyMs);
    line += buf;
  } else {
    line += ",,";
  }
  for (char c : r.lostReason) line += c == ',' ? ';' : c;
  line += '\n';
  std::lock_guard lock(mutex_);
  pending_ += line;
}

void FrameCsvLog::writerLoop() {
  std::string lines;
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, std::chrono::seconds(1), [&] { return stopping_; });
    lines.swap(pending_);
    lock.unlock();
    file_ << lines;
    lines.clear();
    lock.lock();
  }
}

void FrameCsvLog::stopWriter() { stopWorker(writer_, mutex_, wake_, stopping_); }

void FrameCsvLog::finish() {
  stopWriter();
  file_ << pending_;  // the lines added since the writer's last pass
  pending_.clear();
  file_.close();
  if (!file_) throw std::runtime_error("write error");
}

}  // namespace slamdunk
