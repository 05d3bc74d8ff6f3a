#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/Tracker.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace slamdunk {

namespace {

/// Hands the registration's measurements over to the frame's result (its times once).
void report(Registration& registration, TrackingResult& r) {
  r.timings.matching += registration.matchingMs;
  r.timings.ransac += registration.ransacMs;
  registration.matchingMs = registration.ransacMs = 0;
  r.matches = registration.matches.size();
  r.poolSize = registration.poolSize;
  r.inlierPixels = registration.inlierPixels;
  r.rejectedPixels = registration.rejectedPixels;
  if (registration)
    r.inliers = registration.inliers;
  else
    r.lostReason = registration.failure;
}
}  // namespace

Tracker::Tracker(const TrackerOptions& options, const FeatureOptions& featureOptions,
                 std::shared_ptr<KeyframeGraph> graph)
    : options_(options),
      noise_(featureOptions.noise),
      noiseEstimator_(featureOptions.noise, options.noiseEstimation),
      extractor_(featureOptions),
      policy_(options.keyframes),
      culling_(options.culling),
      graph_(graph ? std::move(graph) : std::make_shared<KeyframeGraph>()),
      localMap_(options_.localMap, graph_),
      dense_(options_, *graph_),
      timing_(options_, graph_),
      registrar_(options_, noise_, timing_.sensorTiming(), *graph_, dense_),
      depthOnly_(options_, *graph_, dense_),
      edges_(options_, noise_, *graph_, dense_) {
  for (KeyframeId id : graph_->ids()) {
    nextKeyframeId_ = std::max(nextKeyframeId_, id + 1);
    newestKeyframe_ = id;
  }
  if (graph_->keyframeCount() > 0) {
    // Starting from a saved map: the camera is somewhere in it; the first frames relocalize.
    lost_ = true;
  }
}

Tracker::~Tracker() = default;

TrackingResult Tracker::process(const RgbdFrame& frame) {
  const auto t = SteadyClock::now();
  // Described once, as the frame needs (again only if a loop correction moves the last pose).
  FeatureSet features = extractor_.extract(frame, descriptorTurnAhead());
  const double extractionMs = msSince(t);
  TrackingResult r = process(frame, std::move(features), extractionMs);
  r.timings.total += extractionMs;  // extracted on this thread: part of its time for the frame
  return r;
}

TrackingResult Tracker::process(const RgbdFrame& frame, FeatureSet features, double extractionMs) {
  const auto start = SteadyClock::now();
  TrackingResult r;
  r.timestamp = frame.timestamp();
  if (corrected_.exchange(false)) {
    r.loopCorrected = true;
    globalPoolKeyframes_ = 0;  // its points are where the keyframes were
    if (graph_->contains(lastReference_)) lastPose_ = lastPoseInTodaysMap();
  }
  r.pose = lastPose_;
  registrar_.newFrame(lost_ ? std::nullopt : std::optional<Pose>(lastPose_));

  // Every frame counts for the pools' hand-over, tracked or not.
  auto t = SteadyClock::now();
  r.timings.poolWait = localMap_.beginFrame();
  r.timings.pool = msSince(t);

  t = SteadyClock::now();
  turnDescriptorsToReference(frame, features);
  timing_.beginFrame(frame, features, lastPose_, lost_);
  r.timings.features = extractionMs + msSince(t);
  r.features = features.size();

  auto lostBecause = [&](std::string why) {
    timing_.frameLost();
    lost_ = true;
    ++framesLost_;
    r.status = TrackingStatus::Lost;
    r.lostReason = std::move(why);
    r.timings.total = msSince(start);
    return r;
  };
  const bool enoughFeatures = static_cast<int>(features.size()) >= options_.minFeatures;
  auto fewFeatures = [&] {
    return "only " + std::to_string(features.size()) + " features with valid depth (need " +
           std::to_string(options_.minFeatures) + ")";
  };
  const bool depthOnlyPossible = depthOnly_.possible(lost_, lastReference_);
  if (!enoughFeatures && !depthOnlyPossible) return lostBecause(fewFeatures());

  if (graph_->keyframeCount() == 0) {
    if (options_.localizationOnly) return lostBecause("localization only, and the map is empty");
    r = initialize(frame, std::move(features), r);
    r.timings.total = msSince(start);
    return r;
  }

  const FeaturePool& pool = poolForFrame(frame, r);
  if (!enoughFeatures) r.lostReason = fewFeatures();
  std::optional<Registration> registration;
  if (enoughFeatures) registration = registerByFeatures(pool, frame, features, r);
  if (!registration && depthOnlyPossible)
    registration = registerByDepthOnly(frame, std::move(features), r);
  if (!registration) {
    // Started from a saved map that does not show this place: map on alone rather than wait.
    const bool alone = !trackedOnce_ && options_.newComponentAfter > 0 && enoughFeatures &&
                       (!options_.localizationOnly || options_.extendMap) &&
                       framesLost_ + 1 >= static_cast<size_t>(options_.newComponentAfter);
    if (!alone) return lostBecause(r.lostReason);
    r = initialize(frame, std::move(features), r, newComponentOrigin());
    r.newComponent = true;
    r.timings.total = msSince(start);
    return r;
  }
  r.status = TrackingStatus::Tracked;
  r.lostReason.clear();

  const bool byFeaturesInWindow = !r.depthOnly && !r.relocalized;
  if (!r.depthOnly) learnFromFrame(frame, *registration, r.relocalized);
  for (const auto& revised :
       timing_.reviseOrKeepEarlyFrames(registrar_, frame, *registration, byFeaturesInWindow))
    r.revisedFrames.push_back({revised.timestamp, revised.reference, revised.poseInReference});
  if (!r.depthOnly) report(*registration, r);                // the revision may have replaced it
  if (timing_.takeFirstKeyframeChange()) poolDirty_ = true;  // the pool has its old points
  r.pose = registration->pose;

  updateMap(frame, std::move(*registration), r);
  timing_.endFrame(r.pose, byFeaturesInWindow);
  lastPose_ = r.pose;
  lastReference_ = r.reference;
  lastPoseInReference_ = r.poseInReference;
  lost_ = false;
  trackedOnce_ = true;
  framesLost_ = 0;
  r.timings.total = msSince(start);
  return r;
}

const FeaturePool& Tracker::poolForFrame(const RgbdFrame& frame, TrackingResult& r) {
  const auto t = SteadyClock::now();
  if (mapChanged_.exchange(false) || poolDirty_) {
    // Paper Sec. 4.1: after a keyframe (and its optimization) the window is re-queried
    // around the newest keyframe's current pose.
    localMap_.requestWindow(graph_->pose(newestKeyframe_), frame.intrinsics());
    poolDirty_ = false;
  }
  if (matchingWholeMap_ && !localMap_.windowPending()) matchingWholeMap_ = false;
  r.timings.pool += msSince(t);
  return matchingWholeMap_ ? wholeMapPool(frame.intrinsics(), r) : localMap_.pool();
}

std::optional<Registration> Tracker::registerByFeatures(const FeaturePool& pool,
                                                        const RgbdFrame& frame,
                                                        const FeatureSet& features,
                                                        TrackingResult& r) {
  const bool startingFromMap = lost_ && framesLost_ == 0;  // a loaded map, nothing tracked yet
  if (!startingFromMap) {
    Registration registration =
        registrar_.registerFrame(pool, frame, features, nullptr, timing_.velocityToEstimate());
    if (auto moved = registerInMovedMap(pool, frame, features, registration))
      registration = std::move(*moved);
    if (!registration && !lost_ && graph_->contains(lastReference_)) {
      // A pool holding keyframes far off where they should be (a drifted loop's first
      // keyframes, before its correction) can outvote the rest: try the matches of the
      // keyframes near the reference in the graph alone.
      const std::map<KeyframeId, int> near =
          graph_->rings(lastReference_, options_.loopHopThreshold);
      std::vector<PoolMatch> nearMatches;
      for (const PoolMatch& m : registration.matches)
        if (near.count(pool.feature(m.pool).keyframe)) nearMatches.push_back(m);
      if (nearMatches.size() < registration.matches.size() &&
          static_cast<int>(nearMatches.size()) >= options_.ransac.minInliers) {
        Registration retried = registrar_.registerFrame(pool, frame, features, &nearMatches,
                                                        timing_.velocityToEstimate());
        retried.matchingMs += registration.matchingMs;
        if (retried) registration = std::move(retried);
      }
    }
    if (registration) {
      timing_.refine(registrar_, frame, registration);
      report(registration, r);
      return registration;
    }
    report(registration, r);
  }
  if (startingFromMap ||
      (lost_ && framesLost_ + 1 >= static_cast<size_t>(options_.relocalizeAfter)))
    return relocalize(frame, features, r);
  return std::nullopt;
}

std::optional<Registration> Tracker::registerInMovedMap(const FeaturePool& pool,
                                                        const RgbdFrame& frame,
                                                        const FeatureSet& features,
                                                        const Registration& refused) {
  if (!refused.implausibleJump || lost_ || !graph_->contains(lastReference_)) return std::nullopt;
  const Pose carried = lastPoseInTodaysMap();
  registrar_.newFrame(carried);  // and the keyframe poses read afresh
  Registration again = registrar_.registerFrame(pool, frame, features, &refused.matches,
                                                timing_.velocityToEstimate());
  if (!again) {
    registrar_.newFrame(lastPose_);
    return std::nullopt;
  }
  again.matchingMs += refused.matchingMs;
  again.ransacMs += refused.ransacMs;
  lastPose_ = carried;
  timing_.previousPoseMoved(carried);
  return again;
}

Pose Tracker::lastPoseInTodaysMap() const {
  return orthonormalized(graph_->pose(lastReference_) * lastPoseInReference_);
}

std::optional<Registration> Tracker::relocalize(const RgbdFrame& frame, const FeatureSet& features,
                                                TrackingResult& r) {
  const FeaturePool& wholeMap = wholeMapPool(frame.intrinsics(), r);
  const std::string localReason = r.lostReason;
  Registration registration = registrar_.registerFrame(wholeMap, frame, features);
  report(registration, r);
  if (!registration || static_cast<int>(r.inliers) < options_.relocalizeMinInliers) {
    r.lostReason = (localReason.empty() ? "" : localReason + "; ") +
                   "not relocalized in the map (" + std::to_string(r.inliers) + " inliers)";
    return std::nullopt;
  }
  r.relocalized = true;
  return registration;
}

std::optional<Registration> Tracker::registerByDepthOnly(const RgbdFrame& frame,
                                                         FeatureSet&& features, TrackingResult& r) {
  const auto t = SteadyClock::now();
  DepthOnlyFallback::Result aligned =
      depthOnly_.registerFrame(frame, lastReference_, registrar_.keyframePose(lastReference_),
                               lastPose_, timing_.lastMotion());
  r.timings.ransac += msSince(t);
  if (!aligned.registered) {
    r.lostReason = (r.lostReason.empty() ? "" : r.lostReason + "; ") + aligned.failure;
    return std::nullopt;
  }
  dense_.last = {std::move(aligned.term), lastReference_};
  r.depthOnly = true;
  // Depth covers every cell: the cell count would stay near 1 until the alignment fails.
  r.overlap = aligned.overlap;
  Registration registration;
  registration.registered = true;
  registration.pose = aligned.pose;
  registration.features = std::move(features);
  return registration;
}

void Tracker::learnFromFrame(const RgbdFrame& frame, const Registration& registration,
                             bool relocalized) {
  if (!relocalized) timing_.learnReadout(frame, registration, noise_);
  noiseEstimator_.addFrame(registration.inlierSamples, registration.poseInPool);
  noise_ = noiseEstimator_.current();
}

void Tracker::updateMap(const RgbdFrame& frame, Registration&& registration, TrackingResult& r) {
  // Overlap with the map (paper Sec. 4.2): cells of inlier features (registerByDepthOnly set
  // it for a frame registered by depth alone).
  const FeatureSet& features = registration.features;
  std::vector<cv::Point2f> inlierPixels, allPixels;
  std::map<KeyframeId, size_t> inliersPerKeyframe;
  for (const PoolMatch& m : registration.inlierMatches) {
    inlierPixels.push_back(features.keypoints[m.query].pt);
    ++inliersPerKeyframe[registration.pool->feature(m.pool).keyframe];
  }
  if (!r.depthOnly) {
    for (const auto& kp : features.keypoints) allPixels.push_back(kp.pt);
    r.overlap = policy_.overlap(inlierPixels, allPixels, frame.grey().cols, frame.grey().rows,
                                &r.overlapCells);
  }

  // Registered by depth alone, against the last reference.
  const KeyframeId reference = r.depthOnly ? lastReference_ : dominantKeyframe(inliersPerKeyframe);
  std::vector<KeyframeId> linkable;  // keyframes a new keyframe would get an edge to
  for (const auto& [id, n] : inliersPerKeyframe) {
    if (!graph_->contains(id)) continue;  // culled since the pool was built
    if (static_cast<int>(n) >= options_.loopMinInliers) r.matchedKeyframes.push_back(id);
    if (static_cast<int>(n) >= options_.edgeMinMatches) linkable.push_back(id);
  }

  // A keyframe is linked through the pool it was matched against, and the overlap only means
  // something once the newest keyframe's features are in that pool.
  bool maySpawn = !r.relocalized && !matchingWholeMap_ && localMap_.includes(newestKeyframe_);
  // Paper Sec. 4.4: a frame matching keyframes far apart in the graph becomes a keyframe
  // linked to all of them, whether or not the overlap alone would spawn one. Any new keyframe
  // whose edges join keyframes that far apart closes a metric loop (counted as such).
  bool lowOverlap = policy_.shouldSpawn(r.overlap);
  if (maySpawn && lowOverlap && !r.depthOnly && policy_.options().coveredView > 0)
    lowOverlap = coverage_.coveredShare(features.points, registration.pose, *graph_, linkable) <
                 policy_.options().coveredView;
  bool metricLoopSpawns = true;
  if (options_.localizationOnly) {
    r.outsideMap = !r.relocalized && lowOverlap;
    // The loaded map stays as it is; extended, it grows where it does not cover the view.
    maySpawn = maySpawn && options_.extendMap;
    metricLoopSpawns = false;
  }
  const bool spawn =
      maySpawn && (lowOverlap || (metricLoopSpawns && closesMetricLoop(r.matchedKeyframes)));
  r.loopClosure = spawn && closesMetricLoop(linkable);

  const Pose& pose = registration.pose;
  if (spawn) {
    timing_.keyframeAdded();
    const KeyframeId id = addKeyframe(frame, std::move(registration.features), pose);
    edges_.linkMatches(id, graph_->keyframe(id)->features, registration);
    // Registered by depth alone, the depth associations are the keyframe's only link.
    if (options_.depthEdges || r.depthOnly) edges_.linkDepth(id, pose);
    r.newKeyframe = true;
    r.keyframeId = id;
    r.reference = id;
    r.poseInReference = Pose::Identity();
    poolDirty_ = true;
    r.culledKeyframes = cullRedundantKeyframes(id);
  } else {
    r.reference = reference;
    r.poseInReference = registrar_.keyframePose(reference).inverse() * pose;
    if (r.relocalized || localMap_.shiftNeeded(pose)) {
      // Paper Sec. 4.1 "Shift": the window follows the camera without a new keyframe (and
      // jumps to wherever relocalization put it).
      const auto t = SteadyClock::now();
      localMap_.requestWindow(pose, frame.intrinsics());
      r.timings.pool += msSince(t);
    }
    if (r.relocalized) matchingWholeMap_ = localMap_.windowPending();
  }
}

std::vector<KeyframeId> Tracker::cullRedundantKeyframes(KeyframeId newest) {
  if (culling_.options().redundantShare <= 0) return {};
  // The keyframes the new one matched gained observers; the map's first keyframe stays (the
  // sensor timing refers to it).
  const KeyframeId first = graph_->ids().front();
  std::vector<KeyframeId> candidates;
  for (KeyframeId id : graph_->neighbours(newest))
    if (id != first) candidates.push_back(id);
  return culling_.cull(*graph_, candidates);
}

const FeaturePool& Tracker::wholeMapPool(const CameraIntrinsics& K, TrackingResult& r) {
  const auto t = SteadyClock::now();
  const size_t keyframes = graph_->keyframeCount() + graph_->culledCount();  // ever made
  if (globalPool_.size() == 0 || globalPoolKeyframes_ != keyframes) {
    // No frustum and no budget: the camera may be anywhere in the map, looking anywhere.
    // Built here, not in the background: only a lost camera needs it.
    FeaturePoolOptions o = options_.localMap.pool;
    o.frustumFilter = false;
    o.budget = 0;
    globalPool_ = FeaturePool(o);
    globalPool_.build(*graph_, graph_->ids(), Pose::Identity(), K);
    globalPoolKeyframes_ = keyframes;
  }
  r.timings.pool += msSince(t);
  return globalPool_;
}

TrackingResult Tracker::initialize(const RgbdFrame& frame, FeatureSet&& features, TrackingResult r,
                                   const Pose& origin) {
  // The first frame defines the world: its optical frame, so x-z is the ground-parallel plane.
  // A new component's world is that one moved beside the map.
  const KeyframeId id = addKeyframe(frame, FeatureSet(features), origin);
  timing_.mapStarted(id, frame, features);
  r.status = TrackingStatus::Initialized;
  r.pose = origin;
  r.reference = id;
  r.poseInReference = Pose::Identity();
  r.newKeyframe = true;
  r.keyframeId = id;
  r.features = graph_->keyframe(id)->features.size();
  r.lostReason.clear();
  lastPose_ = origin;
  lastReference_ = id;
  lastPoseInReference_ = Pose::Identity();
  lost_ = false;
  trackedOnce_ = true;
  framesLost_ = 0;
  matchingWholeMap_ = false;
  poolDirty_ = true;
  return r;
}

double Tracker::descriptorTurnAhead() const {
  if (lost_ || !extractor_.turnsDescriptors()) return 0;
  const KeyframePtr reference = graph_->keyframe(lastReference_);
  if (!reference || reference->features.keypoints.empty()) return 0;
  // The reference's descriptor windows' downward axis (turned too if it was), as the last
  // pose sees it near the image centre.
  const float turned = reference->features.keypoints.front().angle;
  const double a = turned >= 0 ? turned * M_PI / 180.0 : 0.0;
  const Eigen::Vector3d down =
      lastPose_.linear().transpose() *
      (graph_->pose(lastReference_).linear() * Eigen::Vector3d(-std::sin(a), std::cos(a), 0));
  if (std::hypot(down.x(), down.y()) < 0.3) return 0;  // looking along it: roll is undefined
  const double roll = std::atan2(-down.x(), down.y()) * 180.0 / M_PI;
  return std::abs(roll) > extractor_.options().surfRollLimitDeg ? roll : 0.0;
}

void Tracker::turnDescriptorsToReference(const RgbdFrame& frame, FeatureSet& features) const {
  const double wanted = descriptorTurnAhead();
  if (!extractor_.describedWith(features, wanted))
    extractor_.describeTurned(frame, features, wanted);
}

Pose Tracker::newComponentOrigin() const {
  // Along x, past the map's farthest keyframe by ten window sides: the new component's camera
  // would have to walk that far back before its window reached another component.
  double farthest = 0;
  for (const auto& [id, pose] : graph_->poses())
    farthest = std::max(farthest, pose.translation().x());
  Pose origin = Pose::Identity();
  origin.translation().x() = farthest + 10 * options_.localMap.windowSize;
  return origin;
}

KeyframeId Tracker::addKeyframe(const RgbdFrame& frame, FeatureSet&& features, const Pose& pose) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = nextKeyframeId_++;
  kf->timestamp = frame.timestamp();
  kf->features = std::move(features);
  kf->intrinsics = frame.intrinsics();
  kf->depthSmallStride = 4;
  subsampleDepth(frame.depth(), kf->depthSmallStride).convertTo(kf->depthSmall, CV_16F);
  if (options_.keepKeyframeImages) {
    kf->colour = frame.colour().empty() ? frame.grey().clone() : frame.colour().clone();
    kf->depth = frame.depth().clone();
  }
  const KeyframeId id = kf->id;
  graph_->addKeyframe(std::move(kf), pose);
  localMap_.keyframeAdded(id);
  newestKeyframe_ = id;
  return id;
}

bool Tracker::closesMetricLoop(const std::vector<KeyframeId>& matched) const {
  // Paper Sec. 4.4: two keyframes seen together but more than R hops apart in the graph.
  for (size_t a = 0; a < matched.size(); ++a)
    for (size_t b = a + 1; b < matched.size(); ++b)
      if (graph_->hopDistance(matched[a], matched[b], options_.loopHopThreshold) < 0) return true;
  return false;
}

}  // namespace slamdunk
