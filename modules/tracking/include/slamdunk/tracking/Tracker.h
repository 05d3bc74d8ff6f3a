#pragma once
// Camera tracking (paper Sec. 4.2, 4.4): features of each frame are matched against the feature
// pool that Local Mapping (LocalMap, Sec. 4.1) keeps for the active keyframe window, the pose
// comes from RANSAC absolute orientation, and the overlap policy or the metric-loop test decides
// when a frame becomes a keyframe. Relocalization against the whole map and registration by
// depth alone take over when the window's features do not register a frame.
//
// The tracker never optimizes: it reports new keyframes, and whoever runs the optimizer (in the
// same or another thread) calls notifyMapChanged() afterwards.

#include <slamdunk/features/FeatureExtractor.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/tracking/KeyframePolicy.h>
#include <slamdunk/tracking/KeypointNoiseEstimator.h>
#include <slamdunk/mapping/LocalMap.h>
#include <slamdunk/tracking/MotionModelError.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <opencv2/core/types.hpp>

#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk {

enum class TrackingStatus { Initialized, Tracked, Lost };
const char* toString(TrackingStatus s);

/// Milliseconds spent in each stage for one frame.
struct StageTimings {
  double features = 0, pool = 0, matching = 0, ransac = 0, total = 0;
  double poolWait = 0;  ///< of `pool`: waiting for a pool's hand-over (offline, deterministic)
};

struct TrackingResult {
  TrackingStatus status = TrackingStatus::Lost;
  double timestamp = 0;
  Pose pose = Pose::Identity();             ///< T_world_frame; the last good pose when lost
  KeyframeId reference = 0;                 ///< reference keyframe (not meaningful when lost)
  Pose poseInReference = Pose::Identity();  ///< T_reference_frame
  bool newKeyframe = false;
  bool loopClosure = false;   ///< the new keyframe was promoted by the metric-loop test
  bool relocalized = false;   ///< registered against the whole map after being lost
  bool depthOnly = false;     ///< registered by depth alone (the features did not register)
  bool skipped = false;       ///< not processed (SlamSystem): its timestamp did not increase
  KeyframeId keyframeId = 0;  ///< id of the new keyframe, if any
  size_t features = 0, matches = 0, inliers = 0;
  size_t poolSize = 0;  ///< features in the pool this frame was matched against
  double overlap = 0;
  int overlapCells = 0;  ///< grid cells the overlap counted (those where the frame has features)
  std::vector<KeyframeId> matchedKeyframes;
  /// For display (the live viewer): image pixels of the frame's pool matches that RANSAC kept
  /// as inliers and of those it rejected, from the last registration tried; empty when none.
  std::vector<cv::Point2f> inlierPixels, rejectedPixels;
  std::string lostReason;
  StageTimings timings;
  /// Frames before this one whose poses were estimated again, oldest first: the frames
  /// registered before the camera's rolling-shutter readout was learned, registered again
  /// once it was (this frame). Whoever keeps the trajectory replaces their poses.
  struct RevisedFrame {
    double timestamp = 0;
    KeyframeId reference = 0;
    Pose poseInReference = Pose::Identity();
  };
  std::vector<RevisedFrame> revisedFrames;
};

class Tracker {
 public:
  Tracker(const TrackerOptions& options, const FeatureOptions& featureOptions,
          std::shared_ptr<KeyframeGraph> graph);
  ~Tracker();

  TrackingResult process(const RgbdFrame& frame);
  /// Keyframe poses changed (local optimization): the next frame asks Local Mapping for the
  /// window around the newest keyframe's pose. Callable from any thread.
  void notifyMapChanged() { mapChanged_ = true; }

  const std::shared_ptr<KeyframeGraph>& graph() const { return graph_; }
  bool isLost() const { return lost_; }
  size_t poolSize() const { return localMap_.pool().size(); }
  const LocalMap& localMap() const { return localMap_; }
  const TrackerOptions& options() const { return options_; }
  const FeatureExtractor& extractor() const { return extractor_; }
  /// The features' noise model now: the INI's until enough frames were measured, then the
  /// estimate (TrackerOptions::noiseEstimation).
  const DepthNoiseModel& noiseModel() const { return noise_; }
  /// The colour camera's rolling-shutter readout in use (ms): the INI's until enough motion
  /// was seen, then the estimate (TrackerOptions::rollingShutterEstimation).
  double rollingShutterMs() const { return sensorTiming_.rollingShutterMs(); }

 private:
  TrackingResult initialize(const RgbdFrame& frame, FeatureSet&& features, TrackingResult r);
  /// Matches against `pool` and estimates the pose; false (with r.lostReason) on failure.
  /// `matches`: the pool matches of these features if already known (else matched here).
  bool registerFrame(const FeaturePool& pool, const RgbdFrame& frame, const FeatureSet& features,
                     TrackingResult& r, std::vector<PoolMatch>& inlierMatches, Pose& pose,
                     const std::vector<PoolMatch>* matches = nullptr,
                     FrameVelocity* velocity = nullptr);
  /// The velocity to undo this frame's timing with and its prior: the last frame's estimate
  /// (or the last motion) if `fromLastFrames`, else zero and a wide prior.
  FrameVelocity predictedVelocity(bool fromLastFrames) const;
  /// The prior's standard deviation: the motion model's measured error within the INI's
  /// bounds (or the INI's widest), or kUnknownVelocityFactor times the widest.
  Twist velocityPriorSigma(bool fromLastFrames) const;
  static constexpr double kUnknownVelocityFactor = 10;
  /// After a frame that followed a tracked one (`consecutive`): the velocity the motion model
  /// predicted at the previous frame is compared with the one its neighbours' poses give.
  void measureMotionModel(const Pose& pose, double intervalMs, bool consecutive);
  static constexpr int kMotionModelWindow = 30;      ///< frames: a second at 30 Hz
  static constexpr int kMotionModelMinSamples = 10;  ///< before the measured width is used
  /// Whether the velocity estimate moved the points by no more than a negligible amount from
  /// those it was compensated with.
  bool velocitySettled(const FrameVelocity& v) const;
  /// Registers the frame again with its points moved (`moved`); on success it replaces the
  /// result, inliers, pose and features (false keeps them).
  bool registerMoved(const FeaturePool& pool, const RgbdFrame& frame, FeatureSet&& moved,
                     const std::vector<PoolMatch>* matches, FrameVelocity* velocity,
                     FeatureSet& features, TrackingResult& r, std::vector<PoolMatch>& inlierMatches,
                     Pose& pose);
  /// The registered inliers' samples with the frame's points moved with `motion` over
  /// `intervalMs` (for the rolling-shutter estimator).
  std::vector<InlierSample> inlierSamplesMovedWith(const RgbdFrame& frame, const FeatureSet& raw,
                                                   const FeaturePool& pool,
                                                   const std::vector<PoolMatch>& inlierMatches,
                                                   const Pose& motion, double intervalMs) const;
  static constexpr int kVelocityPasses = 3;
  /// The camera's motion per frame interval at this frame's time (T_before_after), from the
  /// last tracked frame to `pose`.
  Pose motionAtFrame(const Pose& pose) const;
  /// Second pass of the sensor-timing compensation: with the motion just measured, the
  /// features' points are moved again from `raw` and the frame registered with the same
  /// matches. Keeps the first result if that fails (false).
  bool reregisterWithMeasuredMotion(const FeaturePool& pool, const RgbdFrame& frame,
                                    const FeatureSet& raw, double intervalMs, FeatureSet& features,
                                    TrackingResult& r, std::vector<PoolMatch>& inlierMatches,
                                    Pose& pose, FrameVelocity* velocity = nullptr);
  /// The frame right after the first keyframe, with the sensor timing known: the camera's
  /// motion is measured only now, so the first keyframe's points are undone for it too (stored
  /// as its refined points) and the frame registered again, against a pool of that keyframe
  /// alone (firstPairPool_), twice. False if a re-registration failed (the first result stays).
  /// The first keyframe as measured (its frame and features before any timing compensation),
  /// kept until the next frame was processed.
  struct FirstKeyframe {
    KeyframeId id = 0;
    RgbdFrame frame;
    FeatureSet raw;
  };
  /// Stores the first keyframe's points undone with the camera's `motion` over `intervalMs` as
  /// its refined points, and builds firstPairPool_ of that keyframe alone around `poolCentre`.
  void undoFirstKeyframeTiming(const FirstKeyframe& first, const Pose& motion, double intervalMs,
                               const Pose& poolCentre);
  bool registerFirstPair(const FirstKeyframe& first, const RgbdFrame& frame, const FeatureSet& raw,
                         FeatureSet& features, TrackingResult& r,
                         std::vector<PoolMatch>& inlierMatches, Pose& pose,
                         FrameVelocity* velocity);
  /// The frames tracked between the first keyframe and the readout's first estimate: a
  /// rolling shutter taken for none bent their points (and the first keyframe's) by up to
  /// centimetres on a fast-turning hand-held camera, and moved their poses by as much. Kept
  /// (kMaxEarlyFrames at most, while the first keyframe is the only one) to be registered
  /// again once the readout is learned: reviseEarlyFrames.
  struct EarlyFrame {
    RgbdFrame frame;
    FeatureSet raw;         ///< before any timing compensation
    double intervalMs = 0;  ///< since the frame before it (or the first keyframe)
    Pose pose;
  };
  static constexpr size_t kMaxEarlyFrames = 4;
  /// Keeps this registered frame for reviseEarlyFrames, or gives up on revising when it cannot
  /// be (lost, a second keyframe, too many frames).
  void keepEarlyFrame(const TrackingResult& r, const RgbdFrame& frame, const FeatureSet& raw,
                      double intervalMs, const Pose& pose);
  /// With the readout just learned: the first keyframe's points are undone with it, and the
  /// kept frames and this one registered again in order against that keyframe alone, each
  /// with the motion from the frame before it. The kept frames' new poses go to
  /// r.revisedFrames; this frame's replace its result (registeredPool then points to
  /// firstPairPool_). A failed re-registration keeps the first estimate.
  void reviseEarlyFrames(const RgbdFrame& frame, const FeatureSet& raw, double intervalMs,
                         FeatureSet& features, TrackingResult& r,
                         std::vector<PoolMatch>& inlierMatches, Pose& pose,
                         const FeaturePool*& registeredPool);
  /// Dense depth term against the keyframe sharing most inliers (empty if it has no depth).
  std::optional<DepthAlignmentTerm> depthTermFor(const RgbdFrame& frame, const FeaturePool& pool,
                                                 const std::vector<PoolMatch>& matches,
                                                 const std::vector<bool>& inliers,
                                                 KeyframeId& reference) const;
  /// The current frame's depth samples and a keyframe's depth, for the dense term.
  std::optional<DepthAlignmentTerm> depthTermAgainst(const RgbdFrame& frame,
                                                     KeyframeId reference) const;
  bool depthOnlyPossible() const;
  /// Aligns the frame's depth alone with the last reference keyframe (textureless view); sets
  /// r.overlap to the share of its depth that lands on the keyframe's.
  bool registerByDepthOnly(const RgbdFrame& frame, TrackingResult& r, Pose& pose);
  /// Every keyframe of the map in one pool (rebuilt when keyframes were added since).
  const FeaturePool& wholeMapPool(const CameraIntrinsics& K, TrackingResult& r);
  /// Tries the whole map when the local window does not match (lost, or a loaded map).
  bool relocalize(const RgbdFrame& frame, const FeatureSet& features, TrackingResult& r,
                  std::vector<PoolMatch>& inlierMatches, Pose& pose);
  KeyframeId addKeyframe(const RgbdFrame& frame, FeatureSet&& features, const Pose& pose);
  void linkKeyframe(KeyframeId id, const FeatureSet& features, const FeaturePool& pool,
                    const std::vector<PoolMatch>& inlierMatches);
  /// Adds the depth term's point-to-plane associations (at the keyframe's pose) to the edge
  /// with its reference keyframe, so the local optimization keeps what the alignment measured.
  void linkKeyframeDepth(KeyframeId id, const Pose& pose);
  bool closesMetricLoop(const std::vector<KeyframeId>& matched) const;

  TrackerOptions options_;
  /// The features' noise: weighs them in registration and edges (estimated as frames come).
  DepthNoiseModel noise_;
  KeypointNoiseEstimator noiseEstimator_;
  std::vector<InlierSample> lastInliers_;    ///< of the last successful registration
  Pose lastInliersPose_ = Pose::Identity();  ///< its pose in its pool's world
  FeatureExtractor extractor_;
  KeyframePolicy policy_;
  std::shared_ptr<KeyframeGraph> graph_;
  LocalMap localMap_;
  FeaturePool globalPool_;          ///< every keyframe, for relocalization
  size_t globalPoolKeyframes_ = 0;  ///< keyframe count when globalPool_ was built
  size_t framesLost_ = 0;
  std::optional<DepthAlignmentTerm> lastDepthTerm_;  ///< of the last registered frame
  KeyframeId lastDepthReference_ = 0;
  Pose lastPose_ = Pose::Identity();
  std::optional<Pose> lastMotion_;     ///< between the last two frames, if both were tracked
  std::optional<Twist> lastVelocity_;  ///< the last frame's estimated velocity, if any
  /// The motion model's prediction at the last frame, and what measures it once the next frame
  /// is tracked: the pose before it and the interval between the two.
  struct VelocityPrediction {
    Twist predicted;
    Pose poseBefore;
    double msBefore = 0;
  };
  std::optional<VelocityPrediction> lastPrediction_;
  MotionModelError motionModelError_{kMotionModelWindow, kMotionModelMinSamples};
  double lastMotionMs_ = 0;             ///< the time between those two frames
  std::vector<PoolMatch> lastMatches_;  ///< last frame's pool matches (kept only with SensorTiming)
  double lastTimestamp_ = 0;            ///< of the last frame processed
  SensorTiming sensorTiming_;
  std::optional<FirstKeyframe> firstKeyframe_;
  FeaturePool firstPairPool_;
  std::optional<FirstKeyframe> earlyKeyframe_;  ///< the first keyframe, while frames are kept
  std::vector<EarlyFrame> earlyFrames_;
  RollingShutterEstimator rollingShutter_;
  KeyframeId lastReference_ = 0;  ///< of the last tracked frame
  /// One keyframe's depth prepared for alignment, once per keyframe: frame after frame meets
  /// the same reference (a cache: depthTermAgainst stays const).
  struct ReferenceDepth {
    KeyframeId keyframe = 0;
    cv::Mat depth;    ///< as float, lens distortion taken out (the dense term, depth alone)
    cv::Mat normals;  ///< fitted to depth on first use (depth alone)
  };
  mutable ReferenceDepth referenceDepth_;
  /// Keyframe world poses as first read in the current frame. A frame's pose in the world and
  /// its pose relative to its reference must be computed from the same reading: live, the
  /// optimizer thread may move the keyframe between two reads of the graph.
  mutable std::map<KeyframeId, Pose> posesReadThisFrame_;
  Pose keyframePoseThisFrame(KeyframeId id) const;
  bool lost_ = false;
  bool poolDirty_ = false;
  /// Relocalized, and the window around the new pose is not handed over yet: frames are matched
  /// against the whole map meanwhile (and spawn no keyframe).
  bool matchingWholeMap_ = false;
  std::atomic<bool> mapChanged_{false};
  KeyframeId nextKeyframeId_ = 0;
  KeyframeId newestKeyframe_ = 0;
};

}  // namespace slamdunk
