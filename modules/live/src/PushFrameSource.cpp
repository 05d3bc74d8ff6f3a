#include <slamdunk/live/PushFrameSource.h>

#include <slamdunk/core/RgbdFrame.h>

#include <algorithm>
#include <chrono>

namespace slamdunk::live {

PushFrameSource::PushFrameSource(size_t capacity) : capacity_(std::max<size_t>(1, capacity)) {}

bool PushFrameSource::push(mrpt::obs::CObservation3DRangeScan::Ptr frame) {
  if (!frame) return false;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    if (frames_.size() >= capacity_) {
      frames_.pop_front();
      ++dropped_;
    }
    frames_.push_back(std::move(frame));
  }
  ready_.notify_one();
  return true;
}

void PushFrameSource::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

size_t PushFrameSource::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

mrpt::obs::CObservation3DRangeScan::Ptr PushFrameSource::next(const std::atomic<bool>& stop) {
  std::unique_lock lock(mutex_);
  // `stop` is set without this mutex: wake up regularly to look at it.
  while (frames_.empty() && !closed_ && !stop) ready_.wait_for(lock, std::chrono::milliseconds(50));
  if (stop || frames_.empty()) return nullptr;
  auto frame = std::move(frames_.front());
  frames_.pop_front();
  lock.unlock();
  loadExternalImages(*frame);  // as the other sources hand them over decoded
  return frame;
}

}  // namespace slamdunk::live
