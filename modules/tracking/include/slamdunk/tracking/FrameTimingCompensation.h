#pragma once
// The tracker's part that follows the camera's sensor timing (SensorTiming.h): each frame's
// features are undone for the rolling shutter and the depth offset with the velocity predicted
// from the last frames, and registered again with the motion its own pose measured (with its
// velocity estimated, FrameVelocity); the readout is learned from the registered frames
// (RollingShutterEstimator), and the motion model's error sets the velocity prior's width
// (MotionModelError). Two moments need more: the frame right after the first keyframe, when no
// motion is known yet (the first pair), and the frames registered before the readout was
// learned (the early frames), registered again once it is.
//
// Per frame, in this order: beginFrame; after a successful registration refine, learnReadout
// and reviseOrKeepEarlyFrames; endFrame (or frameLost).

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/tracking/FrameRegistrar.h>
#include <slamdunk/tracking/MotionModelError.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>
#include <slamdunk/tracking/SensorTiming.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <memory>
#include <optional>
#include <vector>

namespace slamdunk {

class FrameTimingCompensation {
 public:
  FrameTimingCompensation(const TrackerOptions& options, std::shared_ptr<KeyframeGraph> graph);

  const SensorTiming& sensorTiming() const { return sensorTiming_; }
  /// The readout in use (ms): the INI's until enough motion was seen, then the estimate.
  double rollingShutterMs() const { return sensorTiming_.rollingShutterMs(); }
  /// The camera's motion between the last two frames, if both were tracked.
  const std::optional<Pose>& lastMotion() const { return lastMotion_; }

  /// A new frame: its features' points are undone with the velocity predicted from the last
  /// frames (nothing to undo without them). `lastPose`: the last tracked frame's; `lost`: the
  /// tracker's state before this frame.
  void beginFrame(const RgbdFrame& frame, FeatureSet& features, const Pose& lastPose, bool lost);
  /// The velocity the frame's first registration estimates with its pose; none if not.
  FrameVelocity* velocityToEstimate() { return estimatingVelocity_ ? &velocity_ : nullptr; }
  /// The map begins with this keyframe (its features as measured).
  void mapStarted(KeyframeId id, const RgbdFrame& frame, const FeatureSet& features);

  /// After the frame registered against `registration.pool`: registered again with the motion
  /// the pose measured (the first pair: against the first keyframe alone, its points undone
  /// too). `registration` is replaced by each re-registration that succeeds.
  void refine(FrameRegistrar& registrar, const RgbdFrame& frame, Registration& registration);
  /// What the registered frame (by its features, in the window or not) tells of the readout.
  void learnReadout(const RgbdFrame& frame, const Registration& registration,
                    const DepthNoiseModel& noise);

  /// A frame whose pose was estimated again (a frame before the readout was learned).
  struct RevisedFrame {
    double timestamp = 0;
    KeyframeId reference = 0;
    Pose poseInReference = Pose::Identity();
  };
  /// While frames are kept for revision: keeps this one, or (the readout just learned)
  /// registers them and this one again against the first keyframe, its points undone with the
  /// readout, and returns their new poses (this frame's replaces `registration`).
  /// `byFeatures`: the frame was registered by its features in the window.
  std::vector<RevisedFrame> reviseOrKeepEarlyFrames(FrameRegistrar& registrar,
                                                    const RgbdFrame& frame,
                                                    Registration& registration, bool byFeatures);
  /// Whether the first keyframe's points were undone (stored as refined points) this frame:
  /// the local pool still holds them as measured. Answers once.
  bool takeFirstKeyframeChange();

  /// The tracked frame's pose. `byFeatures` as above.
  void endFrame(const Pose& pose, bool byFeatures);
  /// The map moved under the frame being processed (a loop correction landed meanwhile): its
  /// motion is measured from the last pose as carried into the moved map.
  void previousPoseMoved(const Pose& previousPose) { frame_.previousPose = previousPose; }
  void frameLost();
  /// A second keyframe: the first is no longer the only one, the early frames are not revised.
  void keyframeAdded();

 private:
  /// The velocity to undo this frame's timing with and its prior: the last frame's estimate
  /// (or the last motion) if `fromLastFrames`, else zero and a wide prior.
  FrameVelocity predictedVelocity(bool fromLastFrames) const;
  /// The prior's standard deviation: the motion model's measured error within the INI's
  /// bounds (or the INI's widest), or kUnknownVelocityFactor times the widest.
  Twist velocityPriorSigma(bool fromLastFrames) const;
  static constexpr double kUnknownVelocityFactor = 10;
  /// After a frame that followed a tracked one (`consecutive`): the velocity the motion model
  /// predicted at the previous frame is compared with the one its neighbours' poses give.
  void measureMotionModel(const Pose& pose, bool consecutive);
  static constexpr int kMotionModelWindow = 30;      ///< frames: a second at 30 Hz
  static constexpr int kMotionModelMinSamples = 10;  ///< before the measured width is used
  /// Whether the velocity estimate moved the points by no more than a negligible amount from
  /// those it was compensated with.
  bool velocitySettled(const FrameVelocity& v) const;
  static constexpr int kVelocityPasses = 3;
  /// The camera's motion per frame interval at this frame's time (T_before_after), from the
  /// last tracked frame to `pose`.
  Pose motionAtFrame(const Pose& pose) const;
  /// Registers the frame again with its points moved (`moved`); on success it replaces
  /// `accepted` (false keeps it).
  static bool registerMoved(FrameRegistrar& registrar, const FeaturePool& pool,
                            const RgbdFrame& frame, FeatureSet&& moved,
                            const std::vector<PoolMatch>* matches, FrameVelocity* velocity,
                            Registration& accepted);
  /// The registered inliers' samples with the frame's points moved with `motion` over
  /// `intervalMs` (for the rolling-shutter estimator).
  std::vector<InlierSample> inlierSamplesMovedWith(const RgbdFrame& frame,
                                                   const Registration& registration,
                                                   const Pose& motion) const;
  /// Second pass: with the motion just measured, the features' points are moved again from
  /// the raw ones and the frame registered with the same matches. False if that failed.
  bool reregisterWithMeasuredMotion(FrameRegistrar& registrar, const RgbdFrame& frame,
                                    Registration& registration);
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
  /// The frame right after the first keyframe, with the sensor timing known: the camera's
  /// motion is measured only now, so the first keyframe's points are undone for it too and the
  /// frame registered again, against a pool of that keyframe alone, twice. False if a
  /// re-registration failed (the first result stays).
  bool registerFirstPair(FrameRegistrar& registrar, const FirstKeyframe& first,
                         const RgbdFrame& frame, Registration& registration);
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
  void keepEarlyFrame(const RgbdFrame& frame, const Pose& pose, bool byFeatures);
  /// With the readout just learned: the first keyframe's points are undone with it, and the
  /// kept frames and this one registered again in order against that keyframe alone, each
  /// with the motion from the frame before it. A failed re-registration keeps the first
  /// estimate.
  std::vector<RevisedFrame> reviseEarlyFrames(FrameRegistrar& registrar, const RgbdFrame& frame,
                                              Registration& registration, bool byFeatures);
  void forgetEarlyFrames();

  const TrackerOptions& options_;
  std::shared_ptr<KeyframeGraph> graph_;
  SensorTiming sensorTiming_;
  RollingShutterEstimator rollingShutter_;
  MotionModelError motionModelError_{kMotionModelWindow, kMotionModelMinSamples};

  double lastTimestamp_ = 0;           ///< of the last frame processed
  std::optional<Pose> lastMotion_;     ///< between the last two frames, if both were tracked
  double lastMotionMs_ = 0;            ///< the time between those two frames
  std::optional<Twist> lastVelocity_;  ///< the last frame's estimated velocity, if any
  /// The motion model's prediction at the last frame, and what measures it once the next frame
  /// is tracked: the pose before it and the interval between the two.
  struct VelocityPrediction {
    Twist predicted;
    Pose poseBefore;
    double msBefore = 0;
  };
  std::optional<VelocityPrediction> lastPrediction_;

  std::optional<FirstKeyframe> firstKeyframe_;  ///< for the next frame
  FeaturePool firstPairPool_;
  bool firstKeyframeChanged_ = false;
  std::optional<FirstKeyframe> earlyKeyframe_;  ///< the first keyframe, while frames are kept
  std::vector<EarlyFrame> earlyFrames_;

  /// The frame being processed (set by beginFrame).
  struct Frame {
    double previousTimestamp = 0;
    double intervalMs = 0;  ///< since the frame before
    bool lost = false;      ///< the tracker's state before it
    /// The last tracked frame's pose: the motion to this frame is measured from it (revised
    /// with the early frames).
    Pose previousPose = Pose::Identity();
    bool compensating = false;           ///< its points undone with the last frames' motion
    std::optional<FirstKeyframe> first;  ///< the first keyframe, if it follows it
    bool firstPair = false;              ///< registered with the first keyframe's points undone
    double appliedReadoutMs = 0;         ///< the readout its registered points were undone with
    FeatureSet raw;                      ///< its features before any timing compensation
  };
  Frame frame_;
  bool estimatingVelocity_ = false;
  FrameVelocity velocity_;
};

}  // namespace slamdunk
