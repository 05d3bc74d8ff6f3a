#include <slamdunk/core/WorkerThread.h>
#include <slamdunk/optimization/LocalOptimization.h>

#include <algorithm>

namespace slamdunk {

LocalOptimization::LocalOptimization(const LocalOptimizerOptions& options,
                                     std::shared_ptr<KeyframeGraph> graph, bool ownThread,
                                     std::function<void()> mapChanged, FollowUp followUp)
    : options_(options),
      graph_(std::move(graph)),
      mapChanged_(std::move(mapChanged)),
      followUp_(std::move(followUp)) {
  if (ownThread) thread_ = std::thread([this] { loop(); });
}

LocalOptimization::~LocalOptimization() { stopWorker(thread_, jobMutex_, jobCv_, stopping_); }

void LocalOptimization::keyframeAdded(KeyframeId root, const DepthNoiseModel& noise) {
  if (!thread_.joinable()) {
    optimizeAround(root, noise);
    return;
  }
  {
    std::lock_guard lock(jobMutex_);
    jobPending_ = true;
    jobRoot_ = root;
    jobNoise_ = noise;
  }
  jobCv_.notify_all();
}

LocalOptimizer LocalOptimization::optimizerFor(const DepthNoiseModel& noise) const {
  LocalOptimizerOptions o = options_;
  o.noise = noise;
  return LocalOptimizer(o);
}

void LocalOptimization::optimizeAround(KeyframeId root, const DepthNoiseModel& noise) {
  const LocalOptimizationReport rep = optimizerFor(noise).optimize(*graph_, root);
  if (mapChanged_) mapChanged_();
  if (rep.status != LocalOptimizationReport::Status::NothingToOptimise) {
    std::lock_guard lock(statsMutex_);
    ++stats_.optimizations;
    stats_.optimizationMs.push_back(rep.timeMs);
    stats_.maxTranslationChange = std::max(stats_.maxTranslationChange, rep.maxTranslationChange);
    stats_.maxRotationChangeDeg = std::max(stats_.maxRotationChangeDeg, rep.maxRotationChangeDeg);
  }
  if (followUp_) followUp_(root, noise);
}

void LocalOptimization::loop() {
  std::unique_lock lock(jobMutex_);
  for (;;) {
    jobCv_.wait(lock, [&] { return jobPending_ || stopping_; });
    if (stopping_) return;
    const KeyframeId root = jobRoot_;
    const DepthNoiseModel noise = jobNoise_;
    jobPending_ = false;
    busy_ = true;
    lock.unlock();
    optimizeAround(root, noise);
    lock.lock();
    busy_ = false;
    jobCv_.notify_all();
  }
}

void LocalOptimization::waitUntilIdle() {
  if (!thread_.joinable()) return;
  std::unique_lock lock(jobMutex_);
  jobCv_.wait(lock, [&] { return !jobPending_ && !busy_; });
}

void LocalOptimization::optimizeWholeGraph(const DepthNoiseModel& noise) {
  const LocalOptimizationReport rep = optimizerFor(noise).optimizeAll(*graph_);
  std::lock_guard lock(statsMutex_);
  if (!rep.usable) return;
  ++stats_.optimizations;
  stats_.optimizationMs.push_back(rep.timeMs);
}

LocalOptimization::Statistics LocalOptimization::statistics() const {
  std::lock_guard lock(statsMutex_);
  return stats_;
}

}  // namespace slamdunk
