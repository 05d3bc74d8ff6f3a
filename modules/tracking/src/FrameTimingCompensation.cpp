#include <slamdunk/tracking/FrameTimingCompensation.h>

#include <cmath>

namespace slamdunk {

namespace {
/// The motion over the interval that ends at a frame (`measured`), extrapolated to the frame's
/// instant by the change from the previous interval's (a hand accelerates quickly: a shaking
/// camera reverses within a few frames, and the previous interval alone points the wrong way).
Pose motionAtIntervalEnd(const Pose& measured, const std::optional<Pose>& previous) {
  if (!previous) return measured;
  return measured * SensorTiming::interpolate(previous->inverse() * measured, 0.5);
}
}  // namespace

FrameTimingCompensation::FrameTimingCompensation(const TrackerOptions& options,
                                                 std::shared_ptr<KeyframeGraph> graph)
    : options_(options),
      graph_(std::move(graph)),
      sensorTiming_(options.sensorTiming),
      rollingShutter_(options.sensorTiming.rollingShutterMs, options.rollingShutterEstimation) {}

void FrameTimingCompensation::beginFrame(const RgbdFrame& frame, FeatureSet& features,
                                         const Pose& lastPose, bool lost) {
  Frame f;
  f.previousTimestamp = lastTimestamp_;
  lastTimestamp_ = frame.timestamp();
  f.intervalMs = 1000.0 * (frame.timestamp() - f.previousTimestamp);
  f.lost = lost;
  f.previousPose = lastPose;
  // Undone with the velocity predicted from the last frames, then again with the velocity
  // estimated with the pose (refine). The frame right after the first has no motion yet: it is
  // registered as measured, then both it and the first keyframe are undone with the motion
  // between them (registerFirstPair; undoing this frame's points alone made its pose worse).
  f.compensating = sensorTiming_.enabled() && lastMotion_ && lastMotionMs_ > 0;
  f.first = std::move(firstKeyframe_);
  firstKeyframe_.reset();
  f.firstPair = f.first && !f.compensating && !lost && graph_->contains(f.first->id) &&
                frame.timestamp() > f.first->frame.timestamp();
  estimatingVelocity_ = options_.estimateFrameVelocity && (f.compensating || f.firstPair);
  velocity_ = FrameVelocity();
  if (estimatingVelocity_) velocity_ = predictedVelocity(f.compensating);
  f.appliedReadoutMs = f.compensating ? sensorTiming_.rollingShutterMs() : 0.0;
  if (f.firstPair) f.raw = features;
  if (f.compensating) {
    f.raw = features;
    if (estimatingVelocity_)
      sensorTiming_.compensate(features, frame, velocity_.compensated);
    else
      sensorTiming_.compensate(features, frame, *lastMotion_, lastMotionMs_);
  }
  frame_ = std::move(f);
}

void FrameTimingCompensation::mapStarted(KeyframeId id, const RgbdFrame& frame,
                                         const FeatureSet& features) {
  lastMotion_.reset();
  if (sensorTiming_.enabled()) firstKeyframe_ = FirstKeyframe{id, frame, features};
}

void FrameTimingCompensation::refine(FrameRegistrar& registrar, const RgbdFrame& frame,
                                     Registration& registration) {
  if (frame_.firstPair) {
    if (registerFirstPair(registrar, *frame_.first, frame, registration))
      frame_.appliedReadoutMs = sensorTiming_.rollingShutterMs();
    if (!rollingShutter_.learned() && options_.rollingShutterEstimation.enabled) {
      earlyKeyframe_ = std::move(frame_.first);
      earlyFrames_.clear();
    }
  }
  if (frame_.compensating && reregisterWithMeasuredMotion(registrar, frame, registration))
    frame_.appliedReadoutMs = sensorTiming_.rollingShutterMs();
}

void FrameTimingCompensation::learnReadout(const RgbdFrame& frame, const Registration& registration,
                                           const DepthNoiseModel& noise) {
  // Learned against the motion between frames: only after a tracked frame, some time before.
  if (frame_.lost || !(frame.timestamp() > frame_.previousTimestamp)) return;
  // Points moved with the frame's own velocity show no rolling shutter left to learn from
  // (velocity and readout act as one product): the estimator gets them moved with that motion
  // instead.
  const Pose motion = motionAtFrame(registration.pose);
  rollingShutter_.addFrame(estimatingVelocity_ ? inlierSamplesMovedWith(frame, registration, motion)
                                               : registration.inlierSamples,
                           registration.poseInPool, motion, frame_.intervalMs, noise,
                           frame_.appliedReadoutMs);
  sensorTiming_.setRollingShutterMs(rollingShutter_.readoutMs());
}

std::vector<FrameTimingCompensation::RevisedFrame> FrameTimingCompensation::reviseOrKeepEarlyFrames(
    FrameRegistrar& registrar, const RgbdFrame& frame, Registration& registration,
    bool byFeatures) {
  if (!earlyKeyframe_) return {};
  if (rollingShutter_.learned())
    return reviseEarlyFrames(registrar, frame, registration, byFeatures);
  keepEarlyFrame(frame, registration.pose, byFeatures);
  return {};
}

bool FrameTimingCompensation::takeFirstKeyframeChange() {
  const bool changed = firstKeyframeChanged_;
  firstKeyframeChanged_ = false;
  return changed;
}

void FrameTimingCompensation::endFrame(const Pose& pose, bool byFeatures) {
  measureMotionModel(pose, !frame_.lost && estimatingVelocity_ && byFeatures);
  lastMotion_ =
      frame_.lost ? std::nullopt : std::optional<Pose>(frame_.previousPose.inverse() * pose);
  lastVelocity_ =
      estimatingVelocity_ && byFeatures ? std::optional<Twist>(velocity_.estimate) : std::nullopt;
  lastMotionMs_ = frame_.intervalMs;
}

void FrameTimingCompensation::frameLost() {
  forgetEarlyFrames();  // the chain of kept frames is broken
  lastVelocity_.reset();
}

void FrameTimingCompensation::keyframeAdded() { forgetEarlyFrames(); }

void FrameTimingCompensation::forgetEarlyFrames() {
  earlyKeyframe_.reset();
  earlyFrames_.clear();
}

Pose FrameTimingCompensation::motionAtFrame(const Pose& pose) const {
  return motionAtIntervalEnd(frame_.previousPose.inverse() * pose, lastMotion_);
}

void FrameTimingCompensation::keepEarlyFrame(const RgbdFrame& frame, const Pose& pose,
                                             bool byFeatures) {
  const bool keepable = byFeatures && !frame_.raw.points.empty() && graph_->keyframeCount() == 1 &&
                        earlyFrames_.size() < kMaxEarlyFrames;
  if (keepable)
    earlyFrames_.push_back({frame, frame_.raw, frame_.intervalMs, pose});
  else
    forgetEarlyFrames();
}

std::vector<FrameTimingCompensation::RevisedFrame> FrameTimingCompensation::reviseEarlyFrames(
    FrameRegistrar& registrar, const RgbdFrame& frame, Registration& registration,
    bool byFeatures) {
  const FirstKeyframe first = std::move(*earlyKeyframe_);
  std::vector<EarlyFrame> frames = std::move(earlyFrames_);
  forgetEarlyFrames();
  if (!byFeatures || frame_.raw.points.empty() || graph_->keyframeCount() != 1 ||
      !graph_->contains(first.id))
    return {};
  frames.push_back({frame, frame_.raw, frame_.intervalMs, registration.pose});
  const Pose keyframePose = graph_->pose(first.id);

  // The camera's motion per frame interval at each instant (index 0 the first keyframe, i + 1
  // frame i), from the poses: at a kept frame, halfway between the motions of the intervals
  // before and after it (a hand accelerates within a frame or two); at the current frame,
  // extrapolated as for any frame; at the keyframe, the first interval's (two noisy intervals
  // extrapolate worse than one, and many frames match that keyframe's points).
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
  Registration scratch;
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
    FrameVelocity* estimated = options_.estimateFrameVelocity ? &velocity : nullptr;
    // This frame's registration replaces its result; the kept frames' only give their poses.
    Registration& accepted = i + 1 == frames.size() ? registration : scratch;
    if (!registerMoved(registrar, firstPairPool_, f.frame, std::move(moved), nullptr, estimated,
                       accepted))
      return false;
    f.pose = accepted.pose;
    return true;
  };
  // Twice: each pass measures the motions the next undoes the points with. A frame that fails
  // to register keeps its last pose, and stops the revision (the next frames' motions need it).
  // This frame's inliers index the pool rebuilt by each pass, whether or not it registered
  // again (the same keyframe's features, in the same order).
  std::vector<bool> registeredAgain(frames.size(), false);
  for (int pass = 0; pass < 2; ++pass) {
    undoFirstKeyframeTiming(first, motionAt(0), frames[0].intervalMs, frames.back().pose);
    size_t i = 0;
    while (i < frames.size() && registerAgain(i)) registeredAgain[i++] = true;
    if (i < frames.size()) break;
  }

  std::vector<RevisedFrame> revised;
  for (size_t i = 0; i + 1 < frames.size(); ++i)
    if (registeredAgain[i])
      revised.push_back(
          {frames[i].frame.timestamp(), first.id, keyframePose.inverse() * frames[i].pose});
  // The motion to this frame is measured from the revised pose before it.
  frame_.previousPose = frames.size() > 1 ? frames[frames.size() - 2].pose : keyframePose;
  return revised;
}

void FrameTimingCompensation::undoFirstKeyframeTiming(const FirstKeyframe& first,
                                                      const Pose& motion, double intervalMs,
                                                      const Pose& poolCentre) {
  FeatureSet points = first.raw;
  sensorTiming_.compensate(points, first.frame, motion, intervalMs);
  PointRefinements refined;
  auto& refinedPoints = refined[first.id];
  for (size_t i = 0; i < points.points.size(); ++i)
    refinedPoints.emplace_back(static_cast<uint32_t>(i), points.points[i]);
  graph_->setPoses({{first.id, graph_->pose(first.id)}}, refined);
  firstPairPool_ = FeaturePool(options_.localMap.pool);
  firstPairPool_.build(*graph_, {first.id}, poolCentre, first.frame.intrinsics());
  firstKeyframeChanged_ = true;
}

bool FrameTimingCompensation::registerFirstPair(FrameRegistrar& registrar,
                                                const FirstKeyframe& first, const RgbdFrame& frame,
                                                Registration& registration) {
  const double intervalMs = 1000.0 * (frame.timestamp() - first.frame.timestamp());
  const Pose firstPose = graph_->pose(first.id);
  FrameVelocity* velocity = velocityToEstimate();
  bool improved = false;
  for (int round = 0; round < 2; ++round) {  // the second with the motion the first measured
    const Pose motion = firstPose.inverse() * registration.pose;  // T_first_this over intervalMs
    undoFirstKeyframeTiming(first, motion, intervalMs, registration.pose);

    // This frame: with its own velocity where it was estimated, else the mean motion.
    FeatureSet again = frame_.raw;
    if (velocity) {
      velocity->prior = SensorTiming::twist(motion, intervalMs);
      velocity->priorSigma = velocityPriorSigma(true);
      velocity->compensated = velocity->estimate;
      sensorTiming_.compensate(again, frame, velocity->compensated);
    } else {
      sensorTiming_.compensate(again, frame, motion, intervalMs);
    }
    if (!registerMoved(registrar, firstPairPool_, frame, std::move(again), nullptr, velocity,
                       registration))
      break;
    improved = true;
    if (velocity) {
      registration.features = frame_.raw;
      sensorTiming_.compensate(registration.features, frame, velocity->estimate);
    }
  }
  return improved;
}

std::vector<InlierSample> FrameTimingCompensation::inlierSamplesMovedWith(
    const RgbdFrame& frame, const Registration& registration, const Pose& motion) const {
  FeatureSet moved = frame_.raw;
  sensorTiming_.compensate(moved, frame, motion, frame_.intervalMs);
  std::vector<InlierSample> samples;
  samples.reserve(registration.inlierMatches.size());
  for (const PoolMatch& m : registration.inlierMatches) {
    const PoolFeature& f = registration.pool->feature(m.pool);
    samples.push_back(
        {moved.points[m.query], f.pointWorld, f.pointKeyframe.z(),
         SensorTiming::rowFraction(moved.keypoints[m.query].pt.y, frame.grey().rows)});
  }
  return samples;
}

FrameVelocity FrameTimingCompensation::predictedVelocity(bool fromLastFrames) const {
  FrameVelocity v;
  if (fromLastFrames)
    v.compensated =
        lastVelocity_ ? *lastVelocity_ : SensorTiming::twist(*lastMotion_, lastMotionMs_);
  v.prior = v.compensated;
  v.priorSigma = velocityPriorSigma(fromLastFrames);
  return v;
}

Twist FrameTimingCompensation::velocityPriorSigma(bool fromLastFrames) const {
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

void FrameTimingCompensation::measureMotionModel(const Pose& pose, bool consecutive) {
  if (!consecutive) {
    lastPrediction_.reset();
    return;
  }
  const Pose& lastPose = frame_.previousPose;
  if (lastPrediction_) {
    // The velocity at the last frame, from the poses on either side of it: the mean of the two
    // intervals' motions (second-order accurate at that frame, unlike the extrapolation).
    const Twist before = SensorTiming::twist(lastPrediction_->poseBefore.inverse() * lastPose,
                                             lastPrediction_->msBefore);
    const Twist after = SensorTiming::twist(lastPose.inverse() * pose, frame_.intervalMs);
    motionModelError_.add(lastPrediction_->predicted, Twist(0.5 * (before + after)));
  }
  lastPrediction_ = VelocityPrediction{SensorTiming::twist(motionAtFrame(pose), frame_.intervalMs),
                                       lastPose, frame_.intervalMs};
}

bool FrameTimingCompensation::reregisterWithMeasuredMotion(FrameRegistrar& registrar,
                                                           const RgbdFrame& frame,
                                                           Registration& registration) {
  const FeaturePool& pool = *registration.pool;
  const std::vector<PoolMatch> matches = registration.matches;
  FrameVelocity* velocity = velocityToEstimate();
  bool registered = false;
  // With the velocity estimated, the points are moved again with each new estimate until it
  // settles: refinePose only follows them to first order (a slanted surface's depth, read
  // where the depth camera saw the point, changes faster than that).
  for (int pass = 0; pass < (velocity ? kVelocityPasses : 1); ++pass) {
    FeatureSet again = frame_.raw;
    if (velocity) {
      // Anchored to the poses: the prior is the motion measured since the last frame,
      // extrapolated to this frame (a prior carried over from frame to frame alone would let
      // the velocity wander where the timing does not observe it, and the pose with it).
      velocity->prior = SensorTiming::twist(motionAtFrame(registration.pose), frame_.intervalMs);
      velocity->compensated = velocity->estimate;
      sensorTiming_.compensate(again, frame, velocity->compensated);
    } else {
      sensorTiming_.compensate(again, frame, motionAtFrame(registration.pose), frame_.intervalMs);
    }
    if (!registerMoved(registrar, pool, frame, std::move(again), &matches, velocity, registration))
      break;
    registered = true;
    if (velocity && velocitySettled(*velocity)) break;
  }
  return registered;
}

bool FrameTimingCompensation::registerMoved(FrameRegistrar& registrar, const FeaturePool& pool,
                                            const RgbdFrame& frame, FeatureSet&& moved,
                                            const std::vector<PoolMatch>* matches,
                                            FrameVelocity* velocity, Registration& accepted) {
  Registration again = registrar.registerFrame(pool, frame, std::move(moved), matches, velocity);
  if (!again) return false;
  again.matchingMs += accepted.matchingMs;
  again.ransacMs += accepted.ransacMs;
  accepted = std::move(again);
  return true;
}

bool FrameTimingCompensation::velocitySettled(const FrameVelocity& v) const {
  // Settled when the change moves no point by more than 0.1 mm (a point 3 m away, seen at the
  // frame's earliest or latest instant).
  const double seconds =
      (sensorTiming_.rollingShutterMs() / 2 + std::abs(sensorTiming_.depthTimeOffsetMs())) / 1000.0;
  const Twist change = v.estimate - v.compensated;
  return (change.head<3>().norm() + 3.0 * change.tail<3>().norm()) * seconds < 1e-4;
}

}  // namespace slamdunk
