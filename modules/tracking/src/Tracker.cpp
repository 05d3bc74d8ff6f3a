#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/Tracker.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace slamdunk {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

/// How many of the inlier matches land in each keyframe.
std::map<KeyframeId, size_t> inlierCountPerKeyframe(const FeaturePool& pool,
                                                    const std::vector<PoolMatch>& matches,
                                                    const std::vector<bool>& inliers) {
  std::map<KeyframeId, size_t> counts;
  for (size_t i = 0; i < matches.size(); ++i)
    if (inliers[i]) ++counts[pool.feature(matches[i].pool).keyframe];
  return counts;
}

/// The keyframe holding the most inliers (the oldest among equals): the frame's reference.
KeyframeId dominantKeyframe(const std::map<KeyframeId, size_t>& counts) {
  KeyframeId best = counts.begin()->first;
  for (const auto& [id, n] : counts)
    if (n > counts.at(best)) best = id;
  return best;
}
}  // namespace

const char* toString(TrackingStatus s) {
  switch (s) {
    case TrackingStatus::Initialized:
      return "initialized";
    case TrackingStatus::Tracked:
      return "tracked";
    case TrackingStatus::Lost:
      return "lost";
  }
  return "?";
}

Tracker::Tracker(const TrackerOptions& options, const FeatureOptions& featureOptions,
                 std::shared_ptr<KeyframeGraph> graph)
    : options_(options),
      noise_(featureOptions.noise),
      noiseEstimator_(featureOptions.noise, options.noiseEstimation),
      extractor_(featureOptions),
      policy_(options.keyframes),
      graph_(graph ? std::move(graph) : std::make_shared<KeyframeGraph>()),
      localMap_(options_.localMap, graph_),
      sensorTiming_(options.sensorTiming),
      rollingShutter_(options.sensorTiming.rollingShutterMs, options.rollingShutterEstimation) {
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
  const auto start = Clock::now();
  TrackingResult r;
  r.timestamp = frame.timestamp();
  r.pose = lastPose_;
  const double previousTimestamp = lastTimestamp_;
  lastTimestamp_ = frame.timestamp();
  posesReadThisFrame_.clear();

  // Every frame counts for the pools' hand-over, tracked or not.
  auto t = Clock::now();
  r.timings.poolWait = localMap_.beginFrame();
  r.timings.pool = msSince(t);

  t = Clock::now();
  FeatureSet features = extractor_.extract(frame);
  // Rolling shutter and depth offset, undone with the velocity predicted from the last frames
  // (nothing to undo without them), then again with the velocity estimated with the pose. The
  // frame right after the first has no motion yet: it is registered as measured, then both it
  // and the first keyframe are undone with the motion between them (registerFirstPair; undoing
  // this frame's points alone made its pose worse: the shake 2.0 -> 3.1 cm).
  const double intervalMs = 1000.0 * (frame.timestamp() - previousTimestamp);
  const bool compensating = sensorTiming_.enabled() && lastMotion_ && lastMotionMs_ > 0;
  std::optional<FirstKeyframe> firstKeyframe = std::move(firstKeyframe_);
  firstKeyframe_.reset();
  const bool firstPair = firstKeyframe && !compensating && !lost_ &&
                         graph_->contains(firstKeyframe->id) &&
                         frame.timestamp() > firstKeyframe->frame.timestamp();
  const bool estimatingVelocity = options_.estimateFrameVelocity && (compensating || firstPair);
  FrameVelocity velocity;
  if (estimatingVelocity) velocity = predictedVelocity(compensating);
  double appliedReadoutMs = compensating ? sensorTiming_.rollingShutterMs() : 0.0;
  FeatureSet rawFeatures;
  if (firstPair) rawFeatures = features;
  if (compensating) {
    rawFeatures = features;
    if (estimatingVelocity)
      sensorTiming_.compensate(features, frame, velocity.compensated);
    else
      sensorTiming_.compensate(features, frame, *lastMotion_, lastMotionMs_);
  }
  r.timings.features = msSince(t);
  r.features = features.size();

  auto lostBecause = [&](std::string why) {
    earlyKeyframe_.reset();  // the chain of kept frames is broken
    earlyFrames_.clear();
    lost_ = true;
    ++framesLost_;
    lastVelocity_.reset();
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
  if (!enoughFeatures && !depthOnlyPossible()) return lostBecause(fewFeatures());

  if (graph_->keyframeCount() == 0) {
    if (sensorTiming_.enabled()) firstKeyframe_ = FirstKeyframe{0, frame, features};
    r = initialize(frame, std::move(features), r);
    if (firstKeyframe_) firstKeyframe_->id = r.keyframeId;
    r.timings.total = msSince(start);
    return r;
  }

  t = Clock::now();
  if (mapChanged_.exchange(false) || poolDirty_) {
    // Paper Sec. 4.1: after a keyframe (and its optimization) the window is re-queried
    // around the newest keyframe's current pose.
    localMap_.requestWindow(graph_->pose(newestKeyframe_), frame.intrinsics());
    poolDirty_ = false;
  }
  if (matchingWholeMap_ && !localMap_.windowPending()) matchingWholeMap_ = false;
  r.timings.pool += msSince(t);

  std::vector<PoolMatch> inlierMatches;
  Pose pose;
  const bool startingFromMap = lost_ && framesLost_ == 0;  // a loaded map, nothing tracked yet
  if (!enoughFeatures) r.lostReason = fewFeatures();
  const FeaturePool& pool =
      matchingWholeMap_ ? wholeMapPool(frame.intrinsics(), r) : localMap_.pool();
  FrameVelocity* estimated = estimatingVelocity ? &velocity : nullptr;
  bool registered =
      enoughFeatures && !startingFromMap &&
      registerFrame(pool, frame, features, r, inlierMatches, pose, nullptr, estimated);
  const FeaturePool* registeredPool = &pool;
  if (registered && firstPair &&
      registerFirstPair(*firstKeyframe, frame, rawFeatures, features, r, inlierMatches, pose,
                        estimated)) {
    registeredPool = &firstPairPool_;
    appliedReadoutMs = sensorTiming_.rollingShutterMs();
  }
  if (registered && firstPair && !rollingShutter_.learned() &&
      options_.rollingShutterEstimation.enabled) {
    earlyKeyframe_ = std::move(firstKeyframe);
    earlyFrames_.clear();
  }
  if (registered && compensating &&
      reregisterWithMeasuredMotion(pool, frame, rawFeatures, intervalMs, features, r, inlierMatches,
                                   pose, estimated))
    appliedReadoutMs = sensorTiming_.rollingShutterMs();
  if (!registered && enoughFeatures &&
      (startingFromMap ||
       (lost_ && framesLost_ + 1 >= static_cast<size_t>(options_.relocalizeAfter))))
    registered = relocalize(frame, features, r, inlierMatches, pose);
  if (!registered && depthOnlyPossible())
    registered = r.depthOnly = registerByDepthOnly(frame, r, pose);
  if (!registered) return lostBecause(r.lostReason);
  r.pose = pose;
  r.status = TrackingStatus::Tracked;
  r.lostReason.clear();
  if (!r.depthOnly) {
    // What this frame tells of the camera: its features' noise, and (if the camera moved
    // since a tracked frame) its rolling shutter.
    if (!lost_ && !r.relocalized && frame.timestamp() > previousTimestamp) {
      // The readout is learned against the motion between frames. Points moved with the
      // frame's own velocity show no rolling shutter left to learn from (velocity and readout
      // act as one product): the estimator gets them moved with that motion instead.
      const Pose motion = motionAtFrame(pose);
      rollingShutter_.addFrame(estimatingVelocity
                                   ? inlierSamplesMovedWith(frame, rawFeatures, *registeredPool,
                                                            inlierMatches, motion, intervalMs)
                                   : lastInliers_,
                               lastInliersPose_, motion, intervalMs, noise_, appliedReadoutMs);
      sensorTiming_.setRollingShutterMs(rollingShutter_.readoutMs());
    }
    noiseEstimator_.addFrame(lastInliers_, lastInliersPose_);
    noise_ = noiseEstimator_.current();
  }
  if (earlyKeyframe_) {
    if (rollingShutter_.learned())
      reviseEarlyFrames(frame, rawFeatures, intervalMs, features, r, inlierMatches, pose,
                        registeredPool);
    else
      keepEarlyFrame(r, frame, rawFeatures, intervalMs, pose);
  }

  // Overlap with the map (paper Sec. 4.2): cells of inlier features, or for a frame registered
  // by depth alone, the share of its depth samples that found their surface (depth covers
  // every cell, so the cell count would stay near 1 until the alignment fails).
  std::vector<cv::Point2f> inlierPixels, allPixels;
  std::map<KeyframeId, size_t> inliersPerKeyframe;
  const FeaturePool& usedPool = r.relocalized ? globalPool_ : *registeredPool;
  for (const PoolMatch& m : inlierMatches) {
    inlierPixels.push_back(features.keypoints[m.query].pt);
    ++inliersPerKeyframe[usedPool.feature(m.pool).keyframe];
  }
  if (!r.depthOnly) {  // registerByDepthOnly set it
    for (const auto& kp : features.keypoints) allPixels.push_back(kp.pt);
    r.overlap = policy_.overlap(inlierPixels, allPixels, frame.grey().cols, frame.grey().rows,
                                &r.overlapCells);
  }

  const KeyframeId reference =
      r.depthOnly ? lastDepthReference_ : dominantKeyframe(inliersPerKeyframe);
  std::vector<KeyframeId> linkable;  // keyframes a new keyframe would get an edge to
  for (const auto& [id, n] : inliersPerKeyframe) {
    if (static_cast<int>(n) >= options_.loopMinInliers) r.matchedKeyframes.push_back(id);
    if (static_cast<int>(n) >= options_.edgeMinMatches) linkable.push_back(id);
  }

  // A keyframe is linked through the pool it was matched against, and the overlap only means
  // something once the newest keyframe's features are in that pool.
  const bool maySpawn = !r.relocalized && !matchingWholeMap_ && localMap_.includes(newestKeyframe_);
  // Paper Sec. 4.4: a frame matching keyframes far apart in the graph becomes a keyframe
  // linked to all of them, whether or not the overlap alone would spawn one. Any new keyframe
  // whose edges join keyframes that far apart closes a metric loop (counted as such).
  const bool spawn =
      maySpawn && (policy_.shouldSpawn(r.overlap) || closesMetricLoop(r.matchedKeyframes));
  r.loopClosure = spawn && closesMetricLoop(linkable);

  if (spawn) {
    earlyKeyframe_.reset();  // the first keyframe is no longer the only one
    earlyFrames_.clear();
    const KeyframeId id = addKeyframe(frame, std::move(features), pose);
    linkKeyframe(id, graph_->keyframe(id)->features, usedPool, inlierMatches);
    // Registered by depth alone, the depth associations are the keyframe's only link.
    if (options_.depthEdges || r.depthOnly) linkKeyframeDepth(id, pose);
    r.newKeyframe = true;
    r.keyframeId = id;
    r.reference = id;
    r.poseInReference = Pose::Identity();
    poolDirty_ = true;
  } else {
    r.reference = reference;
    r.poseInReference = keyframePoseThisFrame(reference).inverse() * pose;
    if (r.relocalized || localMap_.shiftNeeded(pose)) {
      // Paper Sec. 4.1 "Shift": the window follows the camera without a new keyframe (and
      // jumps to wherever relocalization put it).
      t = Clock::now();
      localMap_.requestWindow(pose, frame.intrinsics());
      r.timings.pool += msSince(t);
    }
    if (r.relocalized) matchingWholeMap_ = localMap_.windowPending();
  }
  measureMotionModel(pose, intervalMs,
                     !lost_ && estimatingVelocity && !r.depthOnly && !r.relocalized);
  lastMotion_ = lost_ ? std::nullopt : std::optional<Pose>(lastPose_.inverse() * pose);
  lastVelocity_ = estimatingVelocity && !r.depthOnly && !r.relocalized
                      ? std::optional<Twist>(velocity.estimate)
                      : std::nullopt;
  lastMotionMs_ = intervalMs;
  lastPose_ = pose;
  lastReference_ = r.reference;
  lost_ = false;
  framesLost_ = 0;
  r.timings.total = msSince(start);
  return r;
}

Pose Tracker::keyframePoseThisFrame(KeyframeId id) const {
  const auto it = posesReadThisFrame_.find(id);
  if (it != posesReadThisFrame_.end()) return it->second;
  return posesReadThisFrame_.emplace(id, graph_->pose(id)).first->second;
}

bool Tracker::depthOnlyPossible() const {
  // Only right after a tracked frame: the prediction must be close for the alignment to
  // converge, and a lost camera is found again by relocalization.
  return options_.depthOnlyFallback && options_.depthAlignmentStride > 0 && !lost_ &&
         graph_->contains(lastReference_);
}

bool Tracker::registerByDepthOnly(const RgbdFrame& frame, TrackingResult& r, Pose& pose) {
  const auto t = Clock::now();
  std::optional<DepthAlignmentTerm> term = depthTermAgainst(frame, lastReference_);
  auto fail = [&](const std::string& why) {
    r.lostReason = (r.lostReason.empty() ? "" : r.lostReason + "; ") + why;
    r.timings.ransac += msSince(t);
    return false;
  };
  if (!term) return fail("depth-only: the reference keyframe has no depth");
  term->weight = 1.0;  // alone: its scale does not matter, but 0 (dense term off) would
  // Fitted once per reference keyframe (depthTermAgainst has just made the cache hold
  // lastReference_'s depth): a dark stretch aligns many frames with the same one.
  if (referenceDepth_.normals.empty())
    referenceDepth_.normals = fitPlaneNormals(term->referenceDepth, term->referenceIntrinsics,
                                              options_.depthOnly.normalRadius);
  term->referenceNormals = referenceDepth_.normals;
  // Two predictions, constant velocity (a camera circling an object) and standing still; the
  // accepted alignment that explains more of the frame wins.
  std::vector<Pose> predictions{lastPose_};
  if (lastMotion_) predictions.insert(predictions.begin(), lastPose_ * *lastMotion_);
  std::optional<DepthOnlyResult> best;
  std::string failure;
  for (const Pose& predicted : predictions) {
    DepthOnlyResult c = slamdunk::registerByDepthOnly(predicted, *term, options_.depthOnly);
    if (!c.success) {
      if (failure.empty()) failure = c.failure;
    } else if (!best || c.associatedFraction > best->associatedFraction) {
      best = std::move(c);
    }
  }
  if (!best) return fail(failure);
  if (options_.maxTranslationJump > 0 &&
      translationDistance(best->pose, lastPose_) > options_.maxTranslationJump)
    return fail("depth-only: implausible jump of " +
                std::to_string(translationDistance(best->pose, lastPose_)) + " m");
  pose = best->pose;
  term->maxDistance = options_.depthAlignmentMaxDistance;
  lastDepthTerm_ = std::move(term);
  lastDepthReference_ = lastReference_;
  r.overlap = best->associatedFraction;
  r.timings.ransac += msSince(t);
  return true;
}

namespace {
/// The motion over the interval that ends at a frame (`measured`), extrapolated to the frame's
/// instant by the change from the previous interval's (a hand accelerates quickly: a shaking
/// camera reverses within a few frames, and the previous interval alone points the wrong way).
Pose motionAtIntervalEnd(const Pose& measured, const std::optional<Pose>& previous) {
  if (!previous) return measured;
  return measured * SensorTiming::interpolate(previous->inverse() * measured, 0.5);
}
}  // namespace

Pose Tracker::motionAtFrame(const Pose& pose) const {
  return motionAtIntervalEnd(lastPose_.inverse() * pose, lastMotion_);
}

void Tracker::keepEarlyFrame(const TrackingResult& r, const RgbdFrame& frame, const FeatureSet& raw,
                             double intervalMs, const Pose& pose) {
  const bool keepable = !r.depthOnly && !r.relocalized && !raw.points.empty() &&
                        graph_->keyframeCount() == 1 && earlyFrames_.size() < kMaxEarlyFrames;
  if (keepable) {
    earlyFrames_.push_back({frame, raw, intervalMs, pose});
  } else {
    earlyKeyframe_.reset();
    earlyFrames_.clear();
  }
}

void Tracker::reviseEarlyFrames(const RgbdFrame& frame, const FeatureSet& raw, double intervalMs,
                                FeatureSet& features, TrackingResult& r,
                                std::vector<PoolMatch>& inlierMatches, Pose& pose,
                                const FeaturePool*& registeredPool) {
  const FirstKeyframe first = std::move(*earlyKeyframe_);
  std::vector<EarlyFrame> frames = std::move(earlyFrames_);
  earlyKeyframe_.reset();
  earlyFrames_.clear();
  if (r.depthOnly || r.relocalized || raw.points.empty() || graph_->keyframeCount() != 1 ||
      !graph_->contains(first.id))
    return;
  frames.push_back({frame, raw, intervalMs, pose});
  const Pose keyframePose = graph_->pose(first.id);

  // The camera's motion per frame interval at each instant (index 0 the first keyframe, i + 1
  // frame i), from the poses: at a kept frame, halfway between the motions of the intervals
  // before and after it (a hand accelerates within a frame or two); at the current frame,
  // extrapolated as for any frame; at the keyframe, the first interval's (extrapolated from the
  // first two intervals, without velocities estimated, the shake's first pair erred 1.0 cm
  // instead of 1.6 but its Kinect-like ATE was 5.8 mm instead of 3.4: 160 frames matched that
  // keyframe's points, and two noisy intervals extrapolate worse than one).
  auto motionAt = [&](size_t instant) {
    auto poseAt = [&](size_t j) { return j == 0 ? keyframePose : frames[j - 1].pose; };
    auto interval = [&](size_t j) { return poseAt(j - 1).inverse() * poseAt(j); };  // ends at j
    const size_t last = frames.size();
    if (instant == 0) return interval(1);
    if (instant < last)
      return interval(instant) *
             SensorTiming::interpolate(interval(instant).inverse() * interval(instant + 1), 0.5);
    return motionAtIntervalEnd(interval(last),
                               last >= 2 ? std::optional<Pose>(interval(last - 1)) : std::nullopt);
  };
  auto undoFirstKeyframe = [&] {
    undoFirstKeyframeTiming(first, motionAt(0), frames[0].intervalMs, frames.back().pose);
    poolDirty_ = true;  // the local pool holds the points undone without the readout
  };
  TrackingResult scratchResult = r;
  FeatureSet scratchFeatures;
  std::vector<PoolMatch> scratchInliers;
  auto registerAgain = [&](size_t i) {
    // Each frame's own velocity estimated with its pose (if the INI asks), that motion its
    // prior.
    EarlyFrame& f = frames[i];
    FrameVelocity velocity;
    velocity.prior = SensorTiming::twist(motionAt(i + 1), f.intervalMs);
    velocity.priorSigma = velocityPriorSigma(true);
    velocity.estimate = velocity.compensated = velocity.prior;
    FeatureSet moved = f.raw;
    sensorTiming_.compensate(moved, f.frame, velocity.compensated);
    const bool current = i + 1 == frames.size();
    FrameVelocity* estimated = options_.estimateFrameVelocity ? &velocity : nullptr;
    return registerMoved(firstPairPool_, f.frame, std::move(moved), nullptr, estimated,
                         current ? features : scratchFeatures, current ? r : scratchResult,
                         current ? inlierMatches : scratchInliers, f.pose);
  };
  // Twice: each pass measures the motions the next undoes the points with. A frame that fails
  // to register keeps its last pose, and stops the revision (the next frames' motions need it).
  std::vector<bool> registeredAgain(frames.size(), false);
  for (int pass = 0; pass < 2; ++pass) {
    undoFirstKeyframe();
    size_t i = 0;
    while (i < frames.size() && registerAgain(i)) registeredAgain[i++] = true;
    if (i < frames.size()) break;
  }

  for (size_t i = 0; i + 1 < frames.size(); ++i)
    if (registeredAgain[i])
      r.revisedFrames.push_back(
          {frames[i].frame.timestamp(), first.id, keyframePose.inverse() * frames[i].pose});
  // This frame's inliers index the rebuilt pool, whether or not it registered again (the same
  // keyframe's features, in the same order).
  if (registeredPool == &firstPairPool_ || registeredAgain.back()) {
    pose = r.pose = frames.back().pose;
    registeredPool = &firstPairPool_;
  }
  // The motion to this frame is measured from the revised pose before it.
  lastPose_ = frames.size() > 1 ? frames[frames.size() - 2].pose : keyframePose;
}

void Tracker::undoFirstKeyframeTiming(const FirstKeyframe& first, const Pose& motion,
                                      double intervalMs, const Pose& poolCentre) {
  FeatureSet points = first.raw;
  sensorTiming_.compensate(points, first.frame, motion, intervalMs);
  PointRefinements refined;
  auto& refinedPoints = refined[first.id];
  for (size_t i = 0; i < points.points.size(); ++i)
    refinedPoints.emplace_back(static_cast<uint32_t>(i), points.points[i]);
  graph_->setPoses({{first.id, graph_->pose(first.id)}}, refined);
  firstPairPool_ = FeaturePool(options_.localMap.pool);
  firstPairPool_.build(*graph_, {first.id}, poolCentre, first.frame.intrinsics());
}

bool Tracker::registerFirstPair(const FirstKeyframe& first, const RgbdFrame& frame,
                                const FeatureSet& raw, FeatureSet& features, TrackingResult& r,
                                std::vector<PoolMatch>& inlierMatches, Pose& pose,
                                FrameVelocity* velocity) {
  const double intervalMs = 1000.0 * (frame.timestamp() - first.frame.timestamp());
  const Pose firstPose = graph_->pose(first.id);
  bool improved = false;
  for (int round = 0; round < 2; ++round) {  // the second with the motion the first measured
    const Pose motion = firstPose.inverse() * pose;  // T_first_this over intervalMs
    undoFirstKeyframeTiming(first, motion, intervalMs, pose);

    // This frame: with its own velocity where it was estimated, else the mean motion.
    FeatureSet again = raw;
    if (velocity) {
      velocity->prior = SensorTiming::twist(motion, intervalMs);
      velocity->priorSigma = velocityPriorSigma(true);
      velocity->compensated = velocity->estimate;
      sensorTiming_.compensate(again, frame, velocity->compensated);
    } else {
      sensorTiming_.compensate(again, frame, motion, intervalMs);
    }
    if (!registerMoved(firstPairPool_, frame, std::move(again), nullptr, velocity, features, r,
                       inlierMatches, pose))
      break;
    improved = true;
    if (velocity) {
      features = raw;
      sensorTiming_.compensate(features, frame, velocity->estimate);
    }
  }
  poolDirty_ = true;  // the local pool still holds the first keyframe's points as measured
  return improved;
}

std::vector<InlierSample> Tracker::inlierSamplesMovedWith(
    const RgbdFrame& frame, const FeatureSet& raw, const FeaturePool& pool,
    const std::vector<PoolMatch>& inlierMatches, const Pose& motion, double intervalMs) const {
  FeatureSet moved = raw;
  sensorTiming_.compensate(moved, frame, motion, intervalMs);
  std::vector<InlierSample> samples;
  samples.reserve(inlierMatches.size());
  for (const PoolMatch& m : inlierMatches) {
    const PoolFeature& f = pool.feature(m.pool);
    samples.push_back(
        {moved.points[m.query], f.pointWorld, f.pointKeyframe.z(),
         SensorTiming::rowFraction(moved.keypoints[m.query].pt.y, frame.grey().rows)});
  }
  return samples;
}

FrameVelocity Tracker::predictedVelocity(bool fromLastFrames) const {
  FrameVelocity v;
  if (fromLastFrames)
    v.compensated =
        lastVelocity_ ? *lastVelocity_ : SensorTiming::twist(*lastMotion_, lastMotionMs_);
  v.prior = v.compensated;
  v.priorSigma = velocityPriorSigma(fromLastFrames);
  return v;
}

Twist Tracker::velocityPriorSigma(bool fromLastFrames) const {
  constexpr double kRadians = M_PI / 180;
  Twist widest;
  widest.head<3>().setConstant(options_.velocityPriorSigmaMetres);
  widest.tail<3>().setConstant(options_.velocityPriorSigmaDegrees * kRadians);
  // Nothing known yet (the frame after the first): a prior as wide as a fast hand's motion.
  if (!fromLastFrames) return widest * kUnknownVelocityFactor;
  const std::optional<Twist> measured =
      options_.adaptiveVelocityPrior ? motionModelError_.sigma() : std::nullopt;
  if (!measured) return widest;
  Twist narrowest;
  narrowest.head<3>().setConstant(options_.velocityPriorMinSigmaMetres);
  narrowest.tail<3>().setConstant(options_.velocityPriorMinSigmaDegrees * kRadians);
  return measured->cwiseMax(narrowest).cwiseMin(widest);
}

void Tracker::measureMotionModel(const Pose& pose, double intervalMs, bool consecutive) {
  if (!consecutive) {
    lastPrediction_.reset();
    return;
  }
  if (lastPrediction_) {
    // The velocity at the last frame, from the poses on either side of it: the mean of the two
    // intervals' motions (second-order accurate at that frame, unlike the extrapolation).
    const Twist before = SensorTiming::twist(lastPrediction_->poseBefore.inverse() * lastPose_,
                                             lastPrediction_->msBefore);
    const Twist after = SensorTiming::twist(lastPose_.inverse() * pose, intervalMs);
    motionModelError_.add(lastPrediction_->predicted, Twist(0.5 * (before + after)));
  }
  lastPrediction_ = VelocityPrediction{SensorTiming::twist(motionAtFrame(pose), intervalMs),
                                       lastPose_, intervalMs};
}

bool Tracker::reregisterWithMeasuredMotion(const FeaturePool& pool, const RgbdFrame& frame,
                                           const FeatureSet& raw, double intervalMs,
                                           FeatureSet& features, TrackingResult& r,
                                           std::vector<PoolMatch>& inlierMatches, Pose& pose,
                                           FrameVelocity* velocity) {
  const std::vector<PoolMatch> matches = std::move(lastMatches_);
  bool registered = false;
  // With the velocity estimated, the points are moved again with each new estimate until it
  // settles: refinePose only follows them to first order (a slanted surface's depth, read
  // where the depth camera saw the point, changes faster than that).
  for (int pass = 0; pass < (velocity ? kVelocityPasses : 1); ++pass) {
    FeatureSet again = raw;
    if (velocity) {
      // Anchored to the poses: the prior is the motion measured since the last frame,
      // extrapolated to this frame (a prior carried over from frame to frame alone would let
      // the velocity wander where the timing does not observe it, and the pose with it).
      velocity->prior = SensorTiming::twist(motionAtFrame(pose), intervalMs);
      velocity->compensated = velocity->estimate;
      sensorTiming_.compensate(again, frame, velocity->compensated);
    } else {
      sensorTiming_.compensate(again, frame, motionAtFrame(pose), intervalMs);
    }
    if (!registerMoved(pool, frame, std::move(again), &matches, velocity, features, r,
                       inlierMatches, pose))
      break;
    registered = true;
    if (velocity && velocitySettled(*velocity)) break;
  }
  return registered;
}

bool Tracker::registerMoved(const FeaturePool& pool, const RgbdFrame& frame, FeatureSet&& moved,
                            const std::vector<PoolMatch>* matches, FrameVelocity* velocity,
                            FeatureSet& features, TrackingResult& r,
                            std::vector<PoolMatch>& inlierMatches, Pose& pose) {
  TrackingResult second = r;
  std::vector<PoolMatch> secondInliers;
  Pose secondPose;
  if (!registerFrame(pool, frame, moved, second, secondInliers, secondPose, matches, velocity))
    return false;
  r = std::move(second);
  inlierMatches = std::move(secondInliers);
  pose = secondPose;
  features = std::move(moved);
  return true;
}

bool Tracker::velocitySettled(const FrameVelocity& v) const {
  // Settled when the change moves no point by more than 0.1 mm (a point 3 m away, seen at the
  // frame's earliest or latest instant).
  const double seconds =
      (sensorTiming_.rollingShutterMs() / 2 + std::abs(sensorTiming_.depthTimeOffsetMs())) / 1000.0;
  const Twist change = v.estimate - v.compensated;
  return (change.head<3>().norm() + 3.0 * change.tail<3>().norm()) * seconds < 1e-4;
}

bool Tracker::registerFrame(const FeaturePool& pool, const RgbdFrame& frame,
                            const FeatureSet& features, TrackingResult& r,
                            std::vector<PoolMatch>& inlierMatches, Pose& pose,
                            const std::vector<PoolMatch>* knownMatches, FrameVelocity* velocity) {
  auto t = Clock::now();
  const std::vector<PoolMatch> matches =
      knownMatches ? *knownMatches : pool.match(features.descriptors, options_.ratioThreshold);
  if (sensorTiming_.enabled()) lastMatches_ = matches;  // for the second timing pass only
  r.timings.matching += msSince(t);
  r.matches = matches.size();
  r.poolSize = pool.size();

  t = Clock::now();
  std::vector<Eigen::Vector3d> src, dst;
  std::vector<double> weights;
  src.reserve(matches.size());
  dst.reserve(matches.size());
  for (const PoolMatch& m : matches) {
    const PoolFeature& f = pool.feature(m.pool);
    src.push_back(features.points[m.query]);
    dst.push_back(f.pointWorld);
    weights.push_back(1.0 /
                      (noise_.variance(src.back().z()) + noise_.variance(f.pointKeyframe.z())));
  }
  const RansacResult ransac = ransacAbsoluteOrientation(
      src, dst, options_.ransac, options_.weightedRefit ? &weights : nullptr);
  // Which matches RANSAC kept, for display: a few hundred points, no cost worth measuring.
  r.inlierPixels.clear();
  r.rejectedPixels.clear();
  for (size_t i = 0; i < matches.size(); ++i) {
    const bool inlier = i < ransac.inliers.size() && ransac.inliers[i];
    (inlier ? r.inlierPixels : r.rejectedPixels).push_back(features.keypoints[matches[i].query].pt);
  }
  if (!ransac.success) {
    r.timings.ransac += msSince(t);
    r.lostReason = "only " + std::to_string(ransac.inlierCount) + " RANSAC inliers among " +
                   std::to_string(matches.size()) + " matches";
    return false;
  }
  pose = ransac.transform;
  if (options_.anisotropicRefinement) {
    std::vector<PosePair> pairs;
    pairs.reserve(ransac.inlierCount);
    std::map<KeyframeId, Eigen::Matrix3d> keyframeRotations;
    for (size_t i = 0; i < matches.size(); ++i) {
      if (!ransac.inliers[i]) continue;
      const PoolFeature& f = pool.feature(matches[i].pool);
      // The map point's noise lies along its own keyframe's ray, rotated into the world.
      auto R = keyframeRotations.find(f.keyframe);
      if (R == keyframeRotations.end())
        R = keyframeRotations.emplace(f.keyframe, pool.poseAtBuild(f.keyframe)->linear()).first;
      pairs.push_back({src[i], dst[i], noise_.covariance(src[i]),
                       R->second * noise_.covariance(f.pointKeyframe) * R->second.transpose()});
      if (velocity)
        pairs.back().velocityJacobian = sensorTiming_.velocityJacobian(
            src[i], features.keypoints[matches[i].query].pt.y, frame.grey().rows);
    }
    lastDepthTerm_ = depthTermFor(frame, pool, matches, ransac.inliers, lastDepthReference_);
    pose = refinePose(pose, pairs, {}, lastDepthTerm_ ? &*lastDepthTerm_ : nullptr, velocity);
  }
  // What this registration tells of the features' noise, at the pose in the pool's world.
  std::vector<InlierSample> inlierSamples;
  inlierSamples.reserve(ransac.inlierCount);
  const double rows = frame.grey().rows;
  for (size_t i = 0; i < matches.size(); ++i)
    if (ransac.inliers[i])
      inlierSamples.push_back(
          {src[i], dst[i], pool.feature(matches[i].pool).pointKeyframe.z(),
           SensorTiming::rowFraction(features.keypoints[matches[i].query].pt.y, rows)});
  const Pose poseInPool = pose;
  // The pool's world points carry the keyframe poses of its snapshot, which the optimization
  // may have moved since (a pool is handed over frames after it was asked for). The frame is
  // measured against its dominant keyframe: keep that relative pose, in today's world.
  const KeyframeId dominant =
      dominantKeyframe(inlierCountPerKeyframe(pool, matches, ransac.inliers));
  if (const auto atBuild = pool.poseAtBuild(dominant)) {
    const Pose now = keyframePoseThisFrame(dominant);
    // Re-projected onto a rotation: keyframe poses feed later corrections, and the rounding
    // of each product would otherwise compound from keyframe to keyframe.
    pose = orthonormalized(now * atBuild->inverse() * pose);
    if (lastDepthTerm_) lastDepthTerm_->worldFromReference = now;
  }
  r.timings.ransac += msSince(t);
  if (!lost_ && options_.maxTranslationJump > 0 &&
      translationDistance(pose, lastPose_) > options_.maxTranslationJump) {
    r.lostReason =
        "implausible jump of " + std::to_string(translationDistance(pose, lastPose_)) + " m";
    return false;
  }
  r.inliers = ransac.inlierCount;
  lastInliers_ = std::move(inlierSamples);
  lastInliersPose_ = poseInPool;
  inlierMatches.clear();
  for (size_t i = 0; i < matches.size(); ++i)
    if (ransac.inliers[i]) inlierMatches.push_back(matches[i]);
  return true;
}

std::optional<DepthAlignmentTerm> Tracker::depthTermFor(const RgbdFrame& frame,
                                                        const FeaturePool& pool,
                                                        const std::vector<PoolMatch>& matches,
                                                        const std::vector<bool>& inliers,
                                                        KeyframeId& reference) const {
  if (options_.depthAlignmentWeight <= 0) return std::nullopt;
  const auto counts = inlierCountPerKeyframe(pool, matches, inliers);
  if (counts.empty()) return std::nullopt;
  const KeyframeId best = dominantKeyframe(counts);
  std::optional<DepthAlignmentTerm> term = depthTermAgainst(frame, best);
  if (!term) return term;
  reference = best;
  // In the pool's world, like the feature terms it is refined with.
  if (const auto atBuild = pool.poseAtBuild(best)) term->worldFromReference = *atBuild;
  return term;
}

std::optional<DepthAlignmentTerm> Tracker::depthTermAgainst(const RgbdFrame& frame,
                                                            KeyframeId reference) const {
  const KeyframePtr kf = graph_->keyframe(reference);
  if (!kf || kf->depthSmall.empty()) return std::nullopt;
  // Resampled once per keyframe: frame after frame meets the same reference.
  if (referenceDepth_.keyframe != reference || referenceDepth_.depth.empty()) {
    cv::Mat depth;
    kf->depthSmall.convertTo(depth, CV_32F);
    referenceDepth_ = {reference, undistortedDepth(depth, kf->intrinsics, kf->depthSmallStride),
                       cv::Mat()};
  }
  DepthAlignmentTerm term;
  term.referenceDepth = referenceDepth_.depth;
  term.referenceIntrinsics = scaleIntrinsics(kf->intrinsics, kf->depthSmallStride);
  term.worldFromReference = keyframePoseThisFrame(reference);
  term.weight = options_.depthAlignmentWeight;
  term.maxDistance = options_.depthAlignmentMaxDistance;
  term.centralNormals = options_.depthAlignmentCentralNormals;
  term.framePoints =
      depthSamples(frame, options_.depthAlignmentStride, options_.depthAlignmentMaxDepth);
  return term;
}

bool Tracker::relocalize(const RgbdFrame& frame, const FeatureSet& features, TrackingResult& r,
                         std::vector<PoolMatch>& inlierMatches, Pose& pose) {
  const FeaturePool& wholeMap = wholeMapPool(frame.intrinsics(), r);
  const std::string localReason = r.lostReason;
  if (!registerFrame(wholeMap, frame, features, r, inlierMatches, pose) ||
      static_cast<int>(r.inliers) < options_.relocalizeMinInliers) {
    r.lostReason = (localReason.empty() ? "" : localReason + "; ") +
                   "not relocalized in the map (" + std::to_string(r.inliers) + " inliers)";
    return false;
  }
  r.relocalized = true;
  return true;
}

const FeaturePool& Tracker::wholeMapPool(const CameraIntrinsics& K, TrackingResult& r) {
  const auto t = Clock::now();
  const size_t keyframes = graph_->keyframeCount();
  if (globalPool_.size() == 0 || globalPoolKeyframes_ != keyframes) {
    // No frustum: the camera may be anywhere in the map. Built here, not in the background:
    // only a lost camera needs it.
    FeaturePoolOptions o = options_.localMap.pool;
    o.frustumFilter = false;
    globalPool_ = FeaturePool(o);
    globalPool_.build(*graph_, graph_->ids(), Pose::Identity(), K);
    globalPoolKeyframes_ = keyframes;
  }
  r.timings.pool += msSince(t);
  return globalPool_;
}

TrackingResult Tracker::initialize(const RgbdFrame& frame, FeatureSet&& features,
                                   TrackingResult r) {
  // The first frame defines the world: its optical frame, so x-z is the ground-parallel plane.
  const KeyframeId id = addKeyframe(frame, std::move(features), Pose::Identity());
  r.status = TrackingStatus::Initialized;
  r.pose = Pose::Identity();
  r.reference = id;
  r.newKeyframe = true;
  r.keyframeId = id;
  r.features = graph_->keyframe(id)->features.size();
  lastPose_ = Pose::Identity();
  lastMotion_.reset();
  lastReference_ = id;
  lost_ = false;
  poolDirty_ = true;
  return r;
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

void Tracker::linkKeyframe(KeyframeId id, const FeatureSet& features, const FeaturePool& pool,
                           const std::vector<PoolMatch>& inlierMatches) {
  // Normalised so that a match of two points 1 m away keeps about the paper's weight.
  const double unitVariance = 2 * noise_.variance(1.0);
  const double scaleSigma = options_.keypointScaleSigma;
  const Eigen::Matrix3d R_new = graph_->pose(id).linear();
  std::map<KeyframeId, KeyframePtr> others;
  std::map<KeyframeId, Eigen::Matrix3d> relativeRotation;  // other <- new
  std::map<KeyframeId, std::vector<PointMatch>> perKeyframe;
  for (const PoolMatch& m : inlierMatches) {
    const PoolFeature& f = pool.feature(m.pool);
    auto other = others.find(f.keyframe);
    if (other == others.end())
      other = others.emplace(f.keyframe, graph_->keyframe(f.keyframe)).first;
    // As measured, not as refined: each edge keeps the measurements the optimization weighs.
    const Eigen::Vector3d& pOther = other->second->features.points[f.index];
    const Eigen::Vector3d& pNew = features.points[m.query];
    const double scaleVarOther = noise_.keypointScaleVariance(
        pOther.z(), other->second->features.keypoints[f.index].size, scaleSigma);
    const double scaleVarNew =
        noise_.keypointScaleVariance(pNew.z(), features.keypoints[m.query].size, scaleSigma);
    PointMatch pm{pOther, pNew, 1.0 - m.ratio};  // paper Sec. 4.3: w = 1 - θ'
    pm.featureI = f.index;
    pm.featureJ = m.query;
    switch (options_.edgeInformation) {
      case EdgeInformation::Paper:
        break;
      case EdgeInformation::Isotropic:
        pm.weight *= unitVariance / (noise_.variance(pOther.z()) + noise_.variance(pNew.z()) +
                                     scaleVarOther + scaleVarNew);
        break;
      case EdgeInformation::Anisotropic: {
        auto it = relativeRotation.find(f.keyframe);
        if (it == relativeRotation.end())
          it = relativeRotation
                   .emplace(f.keyframe, graph_->pose(f.keyframe).linear().transpose() * R_new)
                   .first;
        const Eigen::Matrix3d& R = it->second;
        auto across = [](const Eigen::Vector3d& p) {
          const Eigen::Vector3d ray = p.normalized();
          return Eigen::Matrix3d(Eigen::Matrix3d::Identity() - ray * ray.transpose());
        };
        const Eigen::Matrix3d covOther = noise_.covariance(pOther) + scaleVarOther * across(pOther);
        const Eigen::Matrix3d covNew = noise_.covariance(pNew) + scaleVarNew * across(pNew);
        pm.information = unitVariance * (covOther + R * covNew * R.transpose()).inverse();
        break;
      }
    }
    perKeyframe[f.keyframe].push_back(pm);
  }
  for (const auto& [other, pm] : perKeyframe)
    if (static_cast<int>(pm.size()) >= options_.edgeMinMatches) graph_->addMatches(other, id, pm);
}

void Tracker::linkKeyframeDepth(KeyframeId id, const Pose& pose) {
  if (!lastDepthTerm_ || !graph_->contains(lastDepthReference_)) return;
  const auto all = depthCorrespondences(pose, *lastDepthTerm_);
  if (all.empty()) return;
  // Evenly thinned to bound the map's size; the weight keeps the total information.
  const size_t keep = std::min<size_t>(all.size(), options_.depthEdgeMaxMatches);
  const double scale = static_cast<double>(all.size()) / keep;
  const double unitVariance = 2 * noise_.variance(1.0);
  std::vector<PointMatch> matches;
  matches.reserve(keep);
  for (size_t k = 0; k < keep; ++k) {
    const DepthCorrespondence& c = all[k * all.size() / keep];
    // Point-to-plane: e's component along the normal only (a small isotropic part keeps Ω
    // invertible for the per-match residual form).
    PointMatch m{c.referencePoint, c.framePoint,
                 options_.depthEdgeWeight * scale * unitVariance / (c.sigma * c.sigma)};
    m.information = c.normal * c.normal.transpose() + 1e-6 * Eigen::Matrix3d::Identity();
    matches.push_back(m);
  }
  graph_->addMatches(lastDepthReference_, id, matches);
}

bool Tracker::closesMetricLoop(const std::vector<KeyframeId>& matched) const {
  // Paper Sec. 4.4: two keyframes seen together but more than R hops apart in the graph.
  for (size_t a = 0; a < matched.size(); ++a)
    for (size_t b = a + 1; b < matched.size(); ++b)
      if (graph_->hopDistance(matched[a], matched[b], options_.loopHopThreshold) < 0) return true;
  return false;
}

}  // namespace slamdunk
