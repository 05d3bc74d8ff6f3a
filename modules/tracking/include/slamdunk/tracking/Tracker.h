#pragma once
// Camera tracking (paper Sec. 4.2, 4.4): features of each frame are matched against the feature
// pool that Local Mapping (LocalMap, Sec. 4.1) keeps for the active keyframe window, the pose
// comes from RANSAC absolute orientation, and the overlap policy or the metric-loop test decides
// when a frame becomes a keyframe. Relocalization against the whole map and registration by
// depth alone take over when the window's features do not register a frame.
//
// The tracker never optimizes: it reports new keyframes, and whoever runs the optimizer (in the
// same or another thread) calls notifyMapChanged() afterwards.

#include <slamdunk/core/EnumNames.h>
#include <slamdunk/features/FeatureExtractor.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/mapping/KeyframeCulling.h>
#include <slamdunk/mapping/LocalMap.h>
#include <slamdunk/tracking/DenseDepthTerm.h>
#include <slamdunk/tracking/DepthOnlyFallback.h>
#include <slamdunk/tracking/FrameRegistrar.h>
#include <slamdunk/tracking/FrameTimingCompensation.h>
#include <slamdunk/tracking/KeyframeEdges.h>
#include <slamdunk/tracking/KeyframePolicy.h>
#include <slamdunk/tracking/KeypointNoiseEstimator.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/TrackerOptions.h>
#include <slamdunk/tracking/ViewCoverage.h>

#include <opencv2/core/types.hpp>

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk {

enum class TrackingStatus { Initialized, Tracked, Lost };
SLAMDUNK_ENUM_NAMES(TrackingStatus, {{TrackingStatus::Initialized, "initialized"},
                                     {TrackingStatus::Tracked, "tracked"},
                                     {TrackingStatus::Lost, "lost"}});

/// Milliseconds spent in each stage for one frame.
struct StageTimings {
  /// `features`: extracting them, wherever it ran (ahead, on a thread of its own: FramePrefetcher);
  /// `total`: the tracking thread's time for the frame, extraction included when it ran there.
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
  bool loopClosure = false;  ///< the new keyframe was promoted by the metric-loop test
  /// A loop correction (place recognition, SlamSystem) moved the map since the last frame.
  bool loopCorrected = false;
  /// Keyframes the new one made redundant, culled from the map (KeyframeCulling).
  std::vector<KeyframeId> culledKeyframes;
  bool relocalized = false;  ///< registered against the whole map after being lost
  /// Not relocalized in a loaded map for TrackerOptions::newComponentAfter frames: this frame
  /// started a new component of the map (status Initialized), beside the loaded one until place
  /// recognition joins the two.
  bool newComponent = false;
  bool depthOnly = false;  ///< registered by depth alone (the features did not register)
  /// Localization only (TrackerOptions::localizationOnly): tracked, but the map covers less of
  /// the view than a keyframe's spawning threshold: the camera is leaving the mapped area.
  bool outsideMap = false;
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

  /// Extracts the frame's features, described as it needs them (turnDescriptorsToReference()),
  /// then tracks it.
  TrackingResult process(const RgbdFrame& frame);
  /// Tracks a frame whose features were extracted already, in `extractionMs`, with this
  /// tracker's FeatureOptions (FramePrefetcher): the same result as process(frame).
  TrackingResult process(const RgbdFrame& frame, FeatureSet features, double extractionMs);
  /// Keyframe poses changed (local optimization): the next frame asks Local Mapping for the
  /// window around the newest keyframe's pose. Callable from any thread.
  void notifyMapChanged() { mapChanged_ = true; }
  /// A loop correction moved the keyframes: the next frame starts from the last one's pose
  /// relative to its reference keyframe, wherever that keyframe is now (the frame reports
  /// loopCorrected). Callable from any thread.
  void notifyMapCorrected() {
    corrected_ = true;
    mapChanged_ = true;
  }

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
  double rollingShutterMs() const { return timing_.rollingShutterMs(); }

 private:
  /// The frame's features become the first keyframe of a map, or of a new component of it, at
  /// `origin`.
  TrackingResult initialize(const RgbdFrame& frame, FeatureSet&& features, TrackingResult r,
                            const Pose& origin = Pose::Identity());
  /// The turn (degrees, 0: upright) the next frame's SURF windows need to be described as its
  /// reference keyframe's were, as the last pose sees that keyframe: beyond [features]
  /// surf_roll_limit_deg, that roll.
  double descriptorTurnAhead() const;
  /// Describes the frame's features again with descriptorTurnAhead() unless they were already
  /// (described upright ahead, FramePrefetcher: turned here when the frame is rolled).
  void turnDescriptorsToReference(const RgbdFrame& frame, FeatureSet& features) const;
  /// Where a new component's first keyframe goes: beside the whole map, far enough that the
  /// component's active window never holds another component's keyframes.
  Pose newComponentOrigin() const;
  /// The pool this frame is matched against: the local window (asked for again after a new
  /// keyframe or an optimization), or the whole map while a relocalized camera waits for it.
  const FeaturePool& poolForFrame(const RgbdFrame& frame, TrackingResult& r);
  /// Against `pool`, then again with the sensor timing undone with the measured motion; if
  /// that fails, against the whole map when relocalization is due. Reports into `r`.
  std::optional<Registration> registerByFeatures(const FeaturePool& pool, const RgbdFrame& frame,
                                                 const FeatureSet& features, TrackingResult& r);
  /// A registration refused as a jump may be a correction that moved the map after the frame
  /// began (live, loops are corrected on the back end's thread, between any two reads of
  /// poses): judged again from the last pose carried with its reference keyframe to where that
  /// is now. Registered if so; then the frame's motion is measured from there too.
  std::optional<Registration> registerInMovedMap(const FeaturePool& pool, const RgbdFrame& frame,
                                                 const FeatureSet& features,
                                                 const Registration& refused);
  /// The last tracked pose carried with its reference keyframe to where that keyframe is now
  /// (which the graph must hold).
  Pose lastPoseInTodaysMap() const;
  /// Tries the whole map when the local window does not match (lost, or a loaded map).
  std::optional<Registration> relocalize(const RgbdFrame& frame, const FeatureSet& features,
                                         TrackingResult& r);
  /// Aligns the frame's depth alone with the last reference keyframe (textureless view).
  std::optional<Registration> registerByDepthOnly(const RgbdFrame& frame, FeatureSet&& features,
                                                  TrackingResult& r);
  /// What a frame registered by its features tells of the camera: its rolling shutter (if it
  /// moved since a tracked frame) and its features' noise.
  void learnFromFrame(const RgbdFrame& frame, const Registration& registration, bool relocalized);
  /// Overlap with the map, then a new keyframe or the window's shift (paper Sec. 4.1, 4.2, 4.4).
  void updateMap(const RgbdFrame& frame, Registration&& registration, TrackingResult& r);
  /// Every keyframe of the map in one pool (rebuilt when keyframes were added since).
  const FeaturePool& wholeMapPool(const CameraIntrinsics& K, TrackingResult& r);
  KeyframeId addKeyframe(const RgbdFrame& frame, FeatureSet&& features, const Pose& pose);
  bool closesMetricLoop(const std::vector<KeyframeId>& matched) const;
  /// Culls the keyframes the new keyframe made redundant; returns their ids.
  std::vector<KeyframeId> cullRedundantKeyframes(KeyframeId newest);

  TrackerOptions options_;
  /// The features' noise: weighs them in registration and edges (estimated as frames come).
  DepthNoiseModel noise_;
  KeypointNoiseEstimator noiseEstimator_;
  FeatureExtractor extractor_;
  KeyframePolicy policy_;
  ViewCoverage coverage_;
  KeyframeCulling culling_;
  std::shared_ptr<KeyframeGraph> graph_;
  LocalMap localMap_;
  DenseDepthTerm dense_;
  FrameTimingCompensation timing_;
  FrameRegistrar registrar_;
  DepthOnlyFallback depthOnly_;
  KeyframeEdges edges_;
  FeaturePool globalPool_;          ///< every keyframe, for relocalization
  size_t globalPoolKeyframes_ = 0;  ///< keyframe count when globalPool_ was built
  size_t framesLost_ = 0;
  Pose lastPose_ = Pose::Identity();
  KeyframeId lastReference_ = 0;                 ///< of the last tracked frame
  Pose lastPoseInReference_ = Pose::Identity();  ///< the last tracked frame's, in lastReference_
  bool lost_ = false;
  bool trackedOnce_ = false;  ///< a frame of this session was tracked (or started the map)
  bool poolDirty_ = false;
  /// Relocalized, and the window around the new pose is not handed over yet: frames are matched
  /// against the whole map meanwhile (and spawn no keyframe).
  bool matchingWholeMap_ = false;
  std::atomic<bool> mapChanged_{false};
  std::atomic<bool> corrected_{false};
  KeyframeId nextKeyframeId_ = 0;
  KeyframeId newestKeyframe_ = 0;
};

}  // namespace slamdunk
