#include <slamdunk/live/FrameCsvLog.h>

#include <cstdio>
#include <stdexcept>

namespace slamdunk::live {

FrameCsvLog::FrameCsvLog(const std::string& path) : output_(path), file_(output_.tempPath()) {
  if (!file_) throw std::runtime_error("cannot create the frame log '" + path + "'");
  file_ << "index,timestamp,status,grab_s,latency_ms,tracking_ms,keyframes,new_keyframe,"
           "relocalized\n";
  writer_ = std::thread([this] { writerLoop(); });
}

FrameCsvLog::~FrameCsvLog() { stopWriter(); }

void FrameCsvLog::add(const TrackingResult& r, TimePoint grabbed, double latencyMs,
                      size_t keyframes) {
  if (!firstGrab_) firstGrab_ = grabbed;
  const double grabSeconds = std::chrono::duration<double>(grabbed - *firstGrab_).count();
  char line[256];
  std::snprintf(line, sizeof line, "%zu,%.6f,%s,%.3f,%.3f,%.3f,%zu,%d,%d\n", index_++, r.timestamp,
                r.skipped ? "skipped" : toString(r.status), grabSeconds, latencyMs, r.timings.total,
                keyframes, r.newKeyframe ? 1 : 0, r.relocalized ? 1 : 0);
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

void FrameCsvLog::stopWriter() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (writer_.joinable()) writer_.join();
}

void FrameCsvLog::finish() {
  stopWriter();
  file_ << pending_;  // the lines added since the writer's last pass
  pending_.clear();
  file_.close();
  if (!file_) throw std::runtime_error("write error on the frame log '" + output_.tempPath() + "'");
  output_.commit();
}

}  // namespace slamdunk::live
