#include <slamdunk/tracking/DepthNoiseModel.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/Tracker.h>

#include <algorithm>
#include <chrono>

namespace slamdunk {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}
/// Ground-parallel coordinates: x and z of the world (= first camera's optical frame, y down).
Eigen::Vector2d groundPosition(const Pose& p) {
  return {p.translation().x(), p.translation().z()};
}
const DepthNoiseModel kNoise;
double depthNoiseVariance(double z) { return kNoise.variance(z); }
}  // namespace

const char* toString(TrackingStatus s) {
  switch (s) {
    case TrackingStatus::Initialized: return "initialized";
    case TrackingStatus::Tracked: return "tracked";
    case TrackingStatus::Lost: return "lost";
  }
  return "?";
}

Tracker::Tracker(const TrackerOptions& options, const FeatureOptions& featureOptions,
                 std::shared_ptr<KeyframeGraph> graph)
    : options_(options),
      extractor_(featureOptions),
      policy_(options.keyframes),
      graph_(std::move(graph)),
      pool_(options.pool) {
  if (!graph_) graph_ = std::make_shared<KeyframeGraph>();
  for (KeyframeId id : graph_->ids()) {
    nextKeyframeId_ = std::max(nextKeyframeId_, id + 1);
    newestKeyframe_ = id;
  }
}

Tracker::~Tracker() = default;

TrackingResult Tracker::process(const RgbdFrame& frame) {
  const auto start = Clock::now();
  TrackingResult r;
  r.timestamp = frame.timestamp();
  r.pose = lastPose_;

  auto t = Clock::now();
  FeatureSet features = extractor_.extract(frame);
  r.timings.features = msSince(t);
  r.features = features.size();

  auto lostBecause = [&](std::string why) {
    lost_ = true;
    r.status = TrackingStatus::Lost;
    r.lostReason = std::move(why);
    r.timings.total = msSince(start);
    return r;
  };
  if (static_cast<int>(features.size()) < options_.minFeatures)
    return lostBecause("only " + std::to_string(features.size()) +
                       " features with valid depth (need " +
                       std::to_string(options_.minFeatures) + ")");

  if (graph_->keyframeCount() == 0) {
    r = initialize(frame, std::move(features), r);
    r.timings.total = msSince(start);
    return r;
  }

  t = Clock::now();
  if (mapChanged_.exchange(false) || poolDirty_) {
    // Paper Sec. 4.1: after a keyframe (and its optimization) the window is re-queried
    // around the newest keyframe's current pose.
    syncQuadTree();
    rebuildPool(graph_->pose(newestKeyframe_), frame.intrinsics());
  }
  r.timings.pool = msSince(t);

  t = Clock::now();
  const std::vector<PoolMatch> matches =
      pool_.match(features.descriptors, options_.ratioThreshold);
  r.timings.matching = msSince(t);
  r.matches = matches.size();

  t = Clock::now();
  std::vector<Eigen::Vector3d> src, dst;
  std::vector<double> weights;
  src.reserve(matches.size());
  dst.reserve(matches.size());
  for (const PoolMatch& m : matches) {
    const PoolFeature& f = pool_.feature(m.pool);
    src.push_back(features.points[m.query]);
    dst.push_back(f.pointWorld);
    weights.push_back(1.0 / (depthNoiseVariance(src.back().z()) +
                             depthNoiseVariance(f.pointKeyframe.z())));
  }
  const RansacResult ransac = ransacAbsoluteOrientation(
      src, dst, options_.ransac, options_.weightedRefit ? &weights : nullptr);
  r.timings.ransac = msSince(t);
  if (!ransac.success)
    return lostBecause("only " + std::to_string(ransac.inlierCount) + " RANSAC inliers among " +
                       std::to_string(matches.size()) + " matches");
  if (!lost_ && options_.maxTranslationJump > 0 &&
      translationDistance(ransac.transform, lastPose_) > options_.maxTranslationJump)
    return lostBecause("implausible jump of " +
                       std::to_string(translationDistance(ransac.transform, lastPose_)) + " m");

  Pose pose = ransac.transform;
  if (options_.anisotropicRefinement) {
    std::vector<PosePair> pairs;
    pairs.reserve(ransac.inlierCount);
    for (size_t i = 0; i < matches.size(); ++i) {
      if (!ransac.inliers[i]) continue;
      const PoolFeature& f = pool_.feature(matches[i].pool);
      pairs.push_back({src[i], dst[i], kNoise.covariance(src[i]), f.covarianceWorld});
    }
    pose = refinePose(pose, pairs);
  }
  r.pose = pose;
  r.inliers = ransac.inlierCount;
  r.status = TrackingStatus::Tracked;

  std::vector<PoolMatch> inlierMatches;
  std::vector<cv::Point2f> inlierPixels, allPixels;
  std::map<KeyframeId, size_t> inliersPerKeyframe;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!ransac.inliers[i]) continue;
    inlierMatches.push_back(matches[i]);
    inlierPixels.push_back(features.keypoints[matches[i].query].pt);
    ++inliersPerKeyframe[pool_.feature(matches[i].pool).keyframe];
  }
  for (const auto& kp : features.keypoints) allPixels.push_back(kp.pt);
  r.overlap = policy_.overlap(inlierPixels, allPixels, frame.grey().cols, frame.grey().rows);

  KeyframeId reference = inliersPerKeyframe.begin()->first;
  for (const auto& [id, n] : inliersPerKeyframe) {
    if (static_cast<int>(n) >= options_.loopMinInliers) r.matchedKeyframes.push_back(id);
    if (n > inliersPerKeyframe[reference]) reference = id;
  }

  bool spawn = policy_.shouldSpawn(r.overlap);
  if (!spawn && closesMetricLoop(r.matchedKeyframes)) {
    spawn = true;
    r.loopClosure = true;
  }

  if (spawn) {
    const FeatureSet kept = features;  // the graph owns the moved copy
    const KeyframeId id = addKeyframe(frame, std::move(features), pose);
    linkKeyframe(id, kept, inlierMatches);
    r.newKeyframe = true;
    r.keyframeId = id;
    r.reference = id;
    r.poseInReference = Pose::Identity();
    poolDirty_ = true;
  } else {
    r.reference = reference;
    r.poseInReference = graph_->pose(reference).inverse() * pose;
    if (translationDistance(pose, windowCenter_) > options_.windowShift) {
      // Paper Sec. 4.1 "Shift": the window follows the camera without a new keyframe.
      t = Clock::now();
      rebuildPool(pose, frame.intrinsics());
      r.timings.pool += msSince(t);
    }
  }
  lastPose_ = pose;
  lost_ = false;
  r.timings.total = msSince(start);
  return r;
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
  if (options_.keepKeyframeImages) {
    kf->colour = frame.colour().empty() ? frame.grey().clone() : frame.colour().clone();
    kf->depth = frame.depth().clone();
  }
  const KeyframeId id = kf->id;
  graph_->addKeyframe(std::move(kf), pose);
  const Eigen::Vector2d g = groundPosition(pose);
  quadTree_.insert(g.x(), g.y(), id);
  indexedPositions_[id] = g;
  newestKeyframe_ = id;
  return id;
}

void Tracker::linkKeyframe(KeyframeId id, const FeatureSet& features,
                           const std::vector<PoolMatch>& inlierMatches) {
  // Normalised so that a match of two points 1 m away keeps about the paper's weight.
  static const double unitVariance = 2 * kNoise.variance(1.0);
  const Eigen::Matrix3d R_new = graph_->pose(id).linear();
  std::map<KeyframeId, Eigen::Matrix3d> relativeRotation;  // other <- new
  std::map<KeyframeId, std::vector<PointMatch>> perKeyframe;
  for (const PoolMatch& m : inlierMatches) {
    const PoolFeature& f = pool_.feature(m.pool);
    const Eigen::Vector3d& pOther = f.pointKeyframe;
    const Eigen::Vector3d& pNew = features.points[m.query];
    PointMatch pm{pOther, pNew, 1.0 - m.ratio};  // paper Sec. 4.3: w = 1 - θ'
    switch (options_.edgeInformation) {
      case EdgeInformation::Paper:
        break;
      case EdgeInformation::Isotropic:
        pm.weight *= unitVariance / (kNoise.variance(pOther.z()) + kNoise.variance(pNew.z()));
        break;
      case EdgeInformation::Anisotropic: {
        auto it = relativeRotation.find(f.keyframe);
        if (it == relativeRotation.end())
          it = relativeRotation
                   .emplace(f.keyframe, graph_->pose(f.keyframe).linear().transpose() * R_new)
                   .first;
        const Eigen::Matrix3d& R = it->second;
        const Eigen::Matrix3d cov =
            kNoise.covariance(pOther) + R * kNoise.covariance(pNew) * R.transpose();
        pm.information = unitVariance * cov.inverse();
        break;
      }
    }
    perKeyframe[f.keyframe].push_back(pm);
  }
  for (const auto& [other, pm] : perKeyframe)
    if (static_cast<int>(pm.size()) >= options_.edgeMinMatches) graph_->addMatches(other, id, pm);
}

void Tracker::syncQuadTree() {
  for (const auto& [id, pose] : graph_->poses()) {
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

void Tracker::rebuildPool(const Pose& center, const CameraIntrinsics& K) {
  const Eigen::Vector2d g = groundPosition(center);
  std::vector<KeyframeId> active = quadTree_.querySquare(g.x(), g.y(), options_.windowSize);
  pool_.build(*graph_, active, center, K);
  windowCenter_ = center;
  poolDirty_ = false;
}

bool Tracker::closesMetricLoop(const std::vector<KeyframeId>& matched) const {
  // Paper Sec. 4.4: two keyframes seen together but more than R hops apart in the graph.
  for (size_t a = 0; a < matched.size(); ++a)
    for (size_t b = a + 1; b < matched.size(); ++b)
      if (graph_->hopDistance(matched[a], matched[b], options_.loopHopThreshold) < 0) return true;
  return false;
}

}  // namespace slamdunk
