#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/tracking/FrameRegistrar.h>
#include <slamdunk/tracking/RansacAbsoluteOrientation.h>

#include <chrono>

namespace slamdunk {

std::map<KeyframeId, size_t> inlierCountPerKeyframe(const FeaturePool& pool,
                                                    const std::vector<PoolMatch>& matches,
                                                    const std::vector<bool>& inliers) {
  std::map<KeyframeId, size_t> counts;
  for (size_t i = 0; i < matches.size(); ++i)
    if (inliers[i]) ++counts[pool.feature(matches[i].pool).keyframe];
  return counts;
}

KeyframeId dominantKeyframe(const std::map<KeyframeId, size_t>& counts) {
  KeyframeId best = counts.begin()->first;
  for (const auto& [id, n] : counts)
    if (n > counts.at(best)) best = id;
  return best;
}

FrameRegistrar::FrameRegistrar(const TrackerOptions& options, const DepthNoiseModel& noise,
                               const SensorTiming& timing, const KeyframeGraph& graph,
                               DenseDepthTerm& dense)
    : options_(options), noise_(noise), timing_(timing), graph_(graph), dense_(dense) {}

void FrameRegistrar::newFrame(const std::optional<Pose>& lastTracked) {
  lastTracked_ = lastTracked;
  posesReadThisFrame_.clear();
}

Pose FrameRegistrar::keyframePose(KeyframeId id) const {
  const auto it = posesReadThisFrame_.find(id);
  if (it != posesReadThisFrame_.end()) return it->second;
  return posesReadThisFrame_.emplace(id, graph_.pose(id)).first->second;
}

Registration FrameRegistrar::registerFrame(const FeaturePool& pool, const RgbdFrame& frame,
                                           FeatureSet features,
                                           const std::vector<PoolMatch>* knownMatches,
                                           FrameVelocity* velocity) {
  Registration reg;
  reg.pool = &pool;
  auto t = SteadyClock::now();
  reg.matches =
      knownMatches ? *knownMatches : pool.match(features.descriptors, options_.ratioThreshold);
  const std::vector<PoolMatch>& matches = reg.matches;
  reg.matchingMs = msSince(t);
  reg.poolSize = pool.size();

  t = SteadyClock::now();
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
  for (size_t i = 0; i < matches.size(); ++i) {
    const bool inlier = i < ransac.inliers.size() && ransac.inliers[i];
    (inlier ? reg.inlierPixels : reg.rejectedPixels)
        .push_back(features.keypoints[matches[i].query].pt);
  }
  if (!ransac.success) {
    reg.ransacMs = msSince(t);
    reg.failure = "only " + std::to_string(ransac.inlierCount) + " RANSAC inliers among " +
                  std::to_string(matches.size()) + " matches";
    reg.features = std::move(features);
    return reg;
  }
  Pose pose = ransac.transform;
  // The dense term of the last registration refined (the keyframe's depth edge keeps it).
  std::optional<DepthAlignmentTerm>& depthTerm = dense_.last.term;
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
        pairs.back().velocityJacobian = timing_.velocityJacobian(
            src[i], features.keypoints[matches[i].query].pt.y, frame.grey().rows);
    }
    depthTerm = depthTermFor(frame, pool, matches, ransac.inliers, dense_.last.reference);
    pose = refinePose(pose, pairs, {}, depthTerm ? &*depthTerm : nullptr, velocity);
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
    const Pose now = keyframePose(dominant);
    // Re-projected onto a rotation: keyframe poses feed later corrections, and the rounding
    // of each product would otherwise compound from keyframe to keyframe.
    pose = orthonormalized(now * atBuild->inverse() * pose);
    if (depthTerm) depthTerm->worldFromReference = now;
  }
  reg.ransacMs = msSince(t);
  reg.pose = pose;
  reg.features = std::move(features);
  if (lastTracked_ && options_.maxTranslationJump > 0 &&
      translationDistance(pose, *lastTracked_) > options_.maxTranslationJump) {
    reg.failure =
        "implausible jump of " + std::to_string(translationDistance(pose, *lastTracked_)) + " m";
    reg.implausibleJump = true;
    return reg;
  }
  reg.registered = true;
  reg.inliers = ransac.inlierCount;
  reg.inlierSamples = std::move(inlierSamples);
  reg.poseInPool = poseInPool;
  for (size_t i = 0; i < matches.size(); ++i)
    if (ransac.inliers[i]) reg.inlierMatches.push_back(matches[i]);
  return reg;
}

std::optional<DepthAlignmentTerm> FrameRegistrar::depthTermFor(
    const RgbdFrame& frame, const FeaturePool& pool, const std::vector<PoolMatch>& matches,
    const std::vector<bool>& inliers, KeyframeId& reference) const {
  if (options_.depthAlignmentWeight <= 0) return std::nullopt;
  const auto counts = inlierCountPerKeyframe(pool, matches, inliers);
  if (counts.empty()) return std::nullopt;
  const KeyframeId best = dominantKeyframe(counts);
  std::optional<DepthAlignmentTerm> term = dense_.against(frame, best);
  if (!term) return term;
  term->worldFromReference = keyframePose(best);
  reference = best;
  // In the pool's world, like the feature terms it is refined with.
  if (const auto atBuild = pool.poseAtBuild(best)) term->worldFromReference = *atBuild;
  return term;
}

}  // namespace slamdunk
