#include <slamdunk/live/LatestFrameQueue.h>

#include <algorithm>

namespace slamdunk::live {

LatestFrameQueue::LatestFrameQueue(size_t capacity) : capacity_(std::max<size_t>(1, capacity)) {}

bool LatestFrameQueue::push(FramePtr frame, TimePoint grabbed) {
  bool dropped = false;
  {
    std::lock_guard lock(mutex_);
    if (frames_.size() >= capacity_) {
      frames_.pop_front();
      ++dropped_;
      dropped = true;
    }
    frames_.emplace_back(std::move(frame), grabbed);
  }
  ready_.notify_one();
  return dropped;
}

LatestFrameQueue::FramePtr LatestFrameQueue::pop(TimePoint* grabbed) {
  std::unique_lock lock(mutex_);
  ready_.wait(lock, [&] { return !frames_.empty() || closed_; });
  return takeOldest(grabbed);
}

LatestFrameQueue::FramePtr LatestFrameQueue::pop(const std::atomic<bool>& stop) {
  std::unique_lock lock(mutex_);
  while (frames_.empty() && !closed_ && !stop) ready_.wait_for(lock, std::chrono::milliseconds(50));
  return stop ? nullptr : takeOldest(nullptr);
}

LatestFrameQueue::FramePtr LatestFrameQueue::takeOldest(TimePoint* grabbed) {
  if (frames_.empty()) return nullptr;
  FramePtr f = std::move(frames_.front().first);
  if (grabbed) *grabbed = frames_.front().second;
  frames_.pop_front();
  return f;
}

void LatestFrameQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

size_t LatestFrameQueue::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

}  // namespace slamdunk::live
