#include <slamdunk/live/PushFrameSource.h>

#include <slamdunk/core/RgbdFrame.h>

namespace slamdunk::live {

PushFrameSource::PushFrameSource(size_t capacity) : queue_(capacity) {}

bool PushFrameSource::push(mrpt::obs::CObservation3DRangeScan::Ptr frame) {
  if (!frame) return false;
  std::lock_guard lock(closeMutex_);
  if (closed_) return false;
  queue_.push(std::move(frame));
  return true;
}

void PushFrameSource::close() {
  std::lock_guard lock(closeMutex_);
  closed_ = true;
  queue_.close();
}

mrpt::obs::CObservation3DRangeScan::Ptr PushFrameSource::next(const std::atomic<bool>& stop) {
  auto frame = queue_.pop(stop);
  if (frame) loadExternalImages(*frame);  // as the other sources hand them over decoded
  return frame;
}

}  // namespace slamdunk::live
