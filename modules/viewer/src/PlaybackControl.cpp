#include <slamdunk/viewer/PlaybackControl.h>

namespace slamdunk::viewer {

void PlaybackControl::togglePause() {
  {
    std::lock_guard lock(mutex_);
    paused_ = !paused_;
    steps_ = 0;
  }
  changed_.notify_all();
}

void PlaybackControl::step() {
  {
    std::lock_guard lock(mutex_);
    if (paused_)
      ++steps_;
    else
      paused_ = true, steps_ = 1;  // the frame under way finishes, the next one is the step
  }
  changed_.notify_all();
}

void PlaybackControl::release() {
  {
    std::lock_guard lock(mutex_);
    released_ = true;
    paused_ = false;
  }
  changed_.notify_all();
}

bool PlaybackControl::paused() const {
  std::lock_guard lock(mutex_);
  return paused_;
}

void PlaybackControl::waitForTurn() {
  std::unique_lock lock(mutex_);
  const auto mayGo = [&] { return released_ || !paused_ || steps_ > 0; };
  if (!mayGo()) {
    ++waiting_;
    changed_.wait(lock, mayGo);
    --waiting_;
  }
  if (paused_ && steps_ > 0) --steps_;
}

size_t PlaybackControl::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_;
}

}  // namespace slamdunk::viewer
