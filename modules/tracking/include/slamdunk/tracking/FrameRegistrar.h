#pragma once
// Registration of a frame against a feature pool (paper Sec. 4.2): its features are matched
// with the pool's, RANSAC absolute orientation finds the pose and its inliers, and the pose is
// refined under the depth noise (with the dense depth term and the frame's velocity, when
// asked). The tracker registers each frame through it, and so does the sensor-timing
// compensation, with the frame's points moved.

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/features/FeatureExtractor.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/tracking/DenseDepthTerm.h>
#include <slamdunk/tracking/InlierSample.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/SensorTiming.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <opencv2/core/types.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk {

/// One attempt at registering a frame against a pool, successful or not.
struct Registration {
  bool registered = false;
  explicit operator bool() const { return registered; }

  Pose pose = Pose::Identity();          ///< T_world_frame, in today's world
  FeatureSet features;                   ///< the features registered (their points as moved, if so)
  const FeaturePool* pool = nullptr;     ///< registered against; none for depth alone
  std::vector<PoolMatch> matches;        ///< every pool match of the features
  std::vector<PoolMatch> inlierMatches;  ///< those RANSAC kept
  /// The inliers as the camera's estimators read them, at the pose in the pool's world.
  std::vector<InlierSample> inlierSamples;
  Pose poseInPool = Pose::Identity();

  /// For TrackingResult. Its inliers only once registered; `failure` says why not.
  size_t poolSize = 0;
  size_t inliers = 0;
  std::vector<cv::Point2f> inlierPixels, rejectedPixels;  ///< of the matches, for display
  std::string failure;
  /// Refused only for jumping too far from the last tracked pose.
  bool implausibleJump = false;
  /// Milliseconds matching and estimating, not yet reported in a TrackingResult: an attempt
  /// that replaces an accepted one takes over the latter's.
  double matchingMs = 0, ransacMs = 0;
};

class FrameRegistrar {
 public:
  /// `noise` and `timing` are the tracker's, which change as frames come.
  FrameRegistrar(const TrackerOptions& options, const DepthNoiseModel& noise,
                 const SensorTiming& timing, const KeyframeGraph& graph, DenseDepthTerm& dense);

  /// A new frame: keyframe poses are read afresh, and `lastTracked` (none when lost) is the
  /// pose a registration may not jump away from.
  void newFrame(const std::optional<Pose>& lastTracked);

  /// Matches `features` against `pool` (or takes `knownMatches`) and estimates the pose. With
  /// `velocity`, the frame's velocity is estimated with it (its points were moved with
  /// velocity->compensated); velocity->estimate is written whenever the pose was refined.
  Registration registerFrame(const FeaturePool& pool, const RgbdFrame& frame, FeatureSet features,
                             const std::vector<PoolMatch>* knownMatches = nullptr,
                             FrameVelocity* velocity = nullptr);

  /// A keyframe's world pose as first read in the current frame. A frame's pose in the world
  /// and its pose relative to its reference must be computed from the same reading: live, the
  /// optimizer thread may move the keyframe between two reads of the graph.
  Pose keyframePose(KeyframeId id) const;

 private:
  /// Dense depth term against the keyframe sharing most inliers (none if it has no depth, or
  /// the term is off); `reference` becomes that keyframe.
  std::optional<DepthAlignmentTerm> depthTermFor(const RgbdFrame& frame, const FeaturePool& pool,
                                                 const std::vector<PoolMatch>& matches,
                                                 const std::vector<bool>& inliers,
                                                 KeyframeId& reference) const;

  const TrackerOptions& options_;
  const DepthNoiseModel& noise_;
  const SensorTiming& timing_;
  const KeyframeGraph& graph_;
  DenseDepthTerm& dense_;
  std::optional<Pose> lastTracked_;
  mutable std::map<KeyframeId, Pose> posesReadThisFrame_;
};

/// How many of the inlier matches land in each keyframe.
std::map<KeyframeId, size_t> inlierCountPerKeyframe(const FeaturePool& pool,
                                                    const std::vector<PoolMatch>& matches,
                                                    const std::vector<bool>& inliers);
/// The keyframe holding the most inliers (the oldest among equals): the frame's reference.
KeyframeId dominantKeyframe(const std::map<KeyframeId, size_t>& counts);

}  // namespace slamdunk
