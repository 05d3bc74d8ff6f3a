#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/core/WorkerThread.h>
#include <slamdunk/mapping/LocalMap.h>

#include <algorithm>
#include <chrono>

namespace slamdunk {

namespace {
/// Ground-parallel coordinates: x and z of the world (= first camera's optical frame, y down).
Eigen::Vector2d groundPosition(const Pose& p) { return {p.translation().x(), p.translation().z()}; }
}  // namespace

struct LocalMap::Job {
  uint64_t sequence = 0;
  bool window = false;  ///< a window's index, or one new keyframe's
  PoolSnapshot snapshot;
  KeyframeId newest = 0;  ///< newest keyframe in the graph when the snapshot was taken
  uint64_t due = 0;       ///< frame of the hand-over (deterministic mode)
  bool started = false, done = false;
  std::shared_ptr<const PoolPart> part;
};

LocalMap::LocalMap(const LocalMapOptions& options, std::shared_ptr<KeyframeGraph> graph)
    : options_(options), graph_(std::move(graph)), pool_(options.pool) {
  for (KeyframeId id : graph_->ids()) {
    newestKeyframe_ = id;
    haveKeyframe_ = true;
  }
  syncQuadTree();
  if (options_.backgroundPreparation) worker_ = std::thread([this] { workerLoop(); });
}

LocalMap::~LocalMap() { stopWorker(worker_, mutex_, workAvailable_, stopping_); }

double LocalMap::beginFrame() {
  ++frame_;
  if (!options_.backgroundPreparation) return 0;
  const bool deterministic = options_.handoverFrames > 0;
  double waitedMs = 0;
  std::unique_lock lock(mutex_);
  for (;;) {
    // In submission order: what is due (deterministic) or built (live).
    auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const std::shared_ptr<Job>& j) {
      return deterministic ? j->due <= frame_ : j->done;
    });
    if (it == jobs_.end()) break;
    const std::shared_ptr<Job> job = *it;
    if (!job->done) {
      const auto t = SteadyClock::now();
      workDone_.wait(lock, [&] { return job->done; });
      waitedMs += msSince(t);
    }
    jobs_.erase(it);
    lock.unlock();
    handOver(*job);
    lock.lock();
  }
  return waitedMs;
}

void LocalMap::handOver(const Job& job) {
  if (job.window) {
    if (job.sequence < handedOverWindow_) return;  // an older window than the current one
    handedOverWindow_ = job.sequence;
    windowPart_ = job.part;
    windowNewest_ = job.newest;
    haveWindow_ = true;
    // Keyframes in the window's snapshot are in its index (or out of its frustum).
    for (size_t i = keyframesHandedOver_.size(); i-- > 0;) {
      if (keyframesHandedOver_[i] > windowNewest_) continue;
      keyframesHandedOver_.erase(keyframesHandedOver_.begin() + i);
      keyframeParts_.erase(keyframeParts_.begin() + i);
    }
  } else {
    const KeyframeId id = job.snapshot.keyframes.front()->id;
    if (haveWindow_ && id <= windowNewest_) return;  // a newer window has it already
    keyframesHandedOver_.push_back(id);
    keyframeParts_.push_back(job.part);
  }
  rebuildPool();
}

void LocalMap::rebuildPool() {
  pool_ = FeaturePool(options_.pool);
  pool_.append(windowPart_);
  for (const auto& part : keyframeParts_) pool_.append(part);
}

void LocalMap::keyframeAdded(KeyframeId id) {
  const Eigen::Vector2d g = groundPosition(graph_->pose(id));
  quadTree_.insert(g.x(), g.y(), id);
  indexedPositions_[id] = g;
  newestKeyframe_ = id;
  haveKeyframe_ = true;
  // Inline, the window asked for after the keyframe includes it.
  if (options_.backgroundPreparation) submit(PoolSnapshot::of(*graph_, {id}), false, frame_ + 1);
}

void LocalMap::requestWindow(const Pose& center, const CameraIntrinsics& K) {
  syncQuadTree();
  const Eigen::Vector2d g = groundPosition(center);
  compactKeyframes(g);
  PoolSnapshot snapshot =
      PoolSnapshot::of(*graph_, quadTree_.querySquare(g.x(), g.y(), options_.windowSize));
  snapshot.frustum = std::make_pair(center, K);
  requestedCenter_ = center;
  if (!options_.backgroundPreparation) {
    Job job;
    job.sequence = requestedWindow_ = ++nextSequence_;
    job.window = true;
    job.newest = newestKeyframe_;
    const auto t = SteadyClock::now();
    job.part = std::make_shared<const PoolPart>(snapshot, options_.pool);
    {
      std::lock_guard lock(mutex_);
      stats_.windowMs.push_back(msSince(t));
      stats_.windowSizes.push_back(job.part->size());
    }
    handOver(job);
    return;
  }
  if (options_.handoverFrames == 0) {
    // Live, the newest request wins: windows not started yet are never used.
    std::lock_guard lock(mutex_);
    const size_t before = jobs_.size();
    jobs_.erase(std::remove_if(jobs_.begin(), jobs_.end(),
                               [](const auto& j) { return j->window && !j->started; }),
                jobs_.end());
    stats_.windowsSkipped += before - jobs_.size();
  }
  size_t features = 0;
  for (const KeyframePtr& kf : snapshot.keyframes) features += kf->features.size();
  const size_t frames =
      std::min<size_t>(1 + features / static_cast<size_t>(options_.handoverFeaturesPerFrame),
                       static_cast<size_t>(options_.handoverFrames));
  requestedWindow_ = submit(std::move(snapshot), true, frame_ + frames)->sequence;
}

std::shared_ptr<LocalMap::Job> LocalMap::submit(PoolSnapshot snapshot, bool window, uint64_t due) {
  auto job = std::make_shared<Job>();
  job->sequence = ++nextSequence_;
  job->window = window;
  job->snapshot = std::move(snapshot);
  job->newest = newestKeyframe_;
  job->due = due;
  {
    std::lock_guard lock(mutex_);
    jobs_.push_back(job);
  }
  workAvailable_.notify_one();
  return job;
}

void LocalMap::workerLoop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    std::shared_ptr<Job> job;
    workAvailable_.wait(lock, [&] {
      if (stopping_) return true;
      // A new keyframe's own index first: it is small and the tracker needs it next frame.
      for (const bool window : {false, true})
        for (const auto& j : jobs_)
          if (!j->started && j->window == window) {
            job = j;
            return true;
          }
      return false;
    });
    if (stopping_) return;
    job->started = true;
    lock.unlock();
    const auto t = SteadyClock::now();
    auto part = std::make_shared<const PoolPart>(job->snapshot, options_.pool);
    const double ms = msSince(t);
    lock.lock();
    job->part = std::move(part);
    job->done = true;
    (job->window ? stats_.windowMs : stats_.keyframeMs).push_back(ms);
    if (job->window) stats_.windowSizes.push_back(job->part->size());
    workDone_.notify_all();
  }
}

bool LocalMap::shiftNeeded(const Pose& camera) const {
  return translationDistance(camera, requestedCenter_) > options_.windowShift ||
         (options_.windowShiftAngle > 0 &&
          rotationDistance(camera, requestedCenter_) > options_.windowShiftAngle * M_PI / 180);
}

bool LocalMap::windowPending() const { return handedOverWindow_ < requestedWindow_; }

bool LocalMap::includes(KeyframeId id) const {
  return (haveWindow_ && id <= windowNewest_) ||
         std::find(keyframesHandedOver_.begin(), keyframesHandedOver_.end(), id) !=
             keyframesHandedOver_.end();
}

PoolPreparationStats LocalMap::statistics() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void LocalMap::compactKeyframes(const Eigen::Vector2d& windowCentre) {
  // On the tracking thread, when a window is asked for: offline, the same keyframes are
  // compacted at the same frame every run.
  const double reach = 0.5 * options_.windowSize + options_.compactBeyond;
  for (const auto& [id, g] : indexedPositions_) {
    DescriptorStorage storage = DescriptorStorage::Float;
    if (options_.compactBeyond >= 0 && (g - windowCentre).cwiseAbs().maxCoeff() > reach)
      storage = DescriptorStorage::Codes;
    else if (options_.halfFloatDescriptors)
      storage = DescriptorStorage::HalfFloat;
    const auto it = compacted_.find(id);
    if (storage == DescriptorStorage::Float || (it != compacted_.end() && it->second >= storage))
      continue;
    graph_->compactDescriptors(id, storage);
    compacted_[id] = storage;
  }
}

void LocalMap::syncQuadTree() {
  const auto poses = graph_->poses();
  for (auto it = indexedPositions_.begin(); it != indexedPositions_.end();) {
    if (poses.count(it->first)) {
      ++it;
      continue;
    }
    quadTree_.remove(it->second.x(), it->second.y(), it->first);  // culled
    it = indexedPositions_.erase(it);
  }
  for (const auto& [id, pose] : poses) {
    const Eigen::Vector2d g = groundPosition(pose);
    auto it = indexedPositions_.find(id);
    if (it != indexedPositions_.end()) {
      if (it->second == g) continue;
      quadTree_.remove(it->second.x(), it->second.y(), id);
    }
    quadTree_.insert(g.x(), g.y(), id);
    indexedPositions_[id] = g;
  }
}

}  // namespace slamdunk
