#include <slamdunk/live/LivePipeline.h>

namespace slamdunk::live {

namespace {
/// Each counter has one writing thread: a plain load and store is enough.
void keepLongest(std::atomic<std::chrono::steady_clock::rep>& longest,
                 std::chrono::steady_clock::duration d) {
  if (d.count() > longest.load()) longest = d.count();
}
}  // namespace

LivePipeline::LivePipeline(FrameSource& source, SlamSystem& slam, size_t queueCapacity,
                           RawlogRecorder* recorder, size_t maxFrames, FrameHook hook)
    : source_(source),
      slam_(slam),
      recorder_(recorder),
      maxFrames_(maxFrames),
      hook_(std::move(hook)),
      queue_(queueCapacity) {}

LivePipeline::~LivePipeline() {
  requestStop();
  join();
}

void LivePipeline::start() {
  tracker_ = std::thread([this] { trackingLoop(); });
  grabber_ = std::thread([this] { grabberLoop(); });
}

bool LivePipeline::waitUntilOpen(double timeoutSeconds, const std::atomic<bool>& interrupted) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeoutSeconds));
  std::unique_lock lock(mutex_);
  while (openState_ == OpenState::Pending) {
    if (interrupted || Clock::now() >= deadline) return false;
    openChanged_.wait_for(lock, std::chrono::milliseconds(100));
  }
  if (openState_ == OpenState::Failed) throw std::runtime_error(error_);
  return true;
}

void LivePipeline::requestStop() { stop_ = true; }

void LivePipeline::join() {
  if (grabber_.joinable()) grabber_.join();
  if (tracker_.joinable()) tracker_.join();
}

void LivePipeline::grabberLoop() {
  try {
    source_.open();
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(mutex_);
      openState_ = OpenState::Failed;
      error_ = e.what();
    }
    openChanged_.notify_all();
    queue_.close();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    openState_ = OpenState::Open;
  }
  openChanged_.notify_all();
  try {
    Clock::time_point previousGrab;
    while (!stop_) {
      auto frame = source_.next(stop_);
      if (!frame) break;
      const auto grabbed = Clock::now();
      if (received_ == 0)
        firstFrame_ = grabbed.time_since_epoch().count();
      else
        keepLongest(longestSourceGap_, grabbed - previousGrab);
      previousGrab = grabbed;
      ++received_;
      if (recorder_) recorder_->add(*frame);
      queue_.push(std::move(frame), grabbed);  // drops (and counts) the oldest when tracking lags
      if (maxFrames_ && received_ >= maxFrames_) break;
    }
  } catch (const std::exception& e) {
    // A device failure mid-run: keep what was tracked so far, report the error at the end.
    std::lock_guard lock(mutex_);
    error_ = e.what();
  }
  queue_.close();
}

void LivePipeline::trackingLoop() {
  Clock::time_point grabbed;
  while (auto frame = queue_.pop(&grabbed)) {
    keepLongest(longestQueueWait_, Clock::now() - grabbed);
    const TrackingResult r = slam_.process(*frame);
    const double latencyMs =
        std::chrono::duration<double, std::milli>(Clock::now() - grabbed).count();
    {
      std::lock_guard lock(mutex_);
      latenciesMs_.push_back(latencyMs);
    }
    if (hook_) hook_(*frame, r, latencyMs);
    frame.reset();  // free the images before waiting for the next frame
    ++processed_;
    // A frame skipped for a timestamp that did not increase is neither tracked nor lost
    // (SlamSystem counts it).
    if (!r.skipped) {
      if (r.status == TrackingStatus::Lost)
        ++lost_;
      else
        ++tracked_;
      lastStatus_ = static_cast<int>(r.status);
      lastOutsideMap_ = r.outsideMap;
      if (r.outsideMap) ++outsideMap_;
    }
    if (r.newKeyframe) ++keyframes_;
    lastProcessed_ = Clock::now().time_since_epoch().count();
  }
  trackingDone_ = true;
}

LiveCounters LivePipeline::counters() const {
  LiveCounters c;
  c.received = received_;
  c.processed = processed_;
  c.dropped = queue_.dropped();
  c.tracked = tracked_;
  c.lost = lost_;
  c.keyframes = keyframes_;
  c.lastStatus = static_cast<TrackingStatus>(lastStatus_.load());
  c.outsideMap = outsideMap_;
  c.lastOutsideMap = lastOutsideMap_;
  const auto ms = [](Clock::rep ticks) {
    return std::chrono::duration<double, std::milli>(Clock::duration(ticks)).count();
  };
  c.longestSourceGapMs = ms(longestSourceGap_);
  c.longestQueueWaitMs = ms(longestQueueWait_);
  const auto first = firstFrame_.load(), last = lastProcessed_.load();
  if (first && last > first)
    c.activeSeconds = std::chrono::duration<double>(Clock::duration(last - first)).count();
  return c;
}

std::vector<double> LivePipeline::latenciesMs() const {
  std::lock_guard lock(mutex_);
  return latenciesMs_.toVector();
}

std::string LivePipeline::error() const {
  std::lock_guard lock(mutex_);
  return openState_ == OpenState::Open ? error_ : std::string();
}

}  // namespace slamdunk::live
