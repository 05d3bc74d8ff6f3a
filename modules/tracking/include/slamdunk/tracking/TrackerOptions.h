#pragma once
// Camera Tracking's parameters: section [tracker] (paper Table 3 names in comments).

#include <slamdunk/core/EnumNames.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/mapping/KeyframeCulling.h>
#include <slamdunk/mapping/LocalMap.h>
#include <slamdunk/tracking/DepthOnlyRegistration.h>
#include <slamdunk/tracking/KeyframePolicy.h>
#include <slamdunk/tracking/KeypointNoiseEstimator.h>
#include <slamdunk/tracking/RansacAbsoluteOrientation.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>
#include <slamdunk/tracking/SensorTiming.h>

#include <mrpt/config/CLoadableOptions.h>

namespace slamdunk {

/// How graph edges weigh their matches: the paper's w = 1 - θ' alone, or also by the depth
/// noise of the two points, as a scalar or as a ray-aligned (anisotropic) information matrix.
enum class EdgeInformation { Paper, Isotropic, Anisotropic };
SLAMDUNK_ENUM_NAMES(EdgeInformation, {{EdgeInformation::Paper, "paper"},
                                      {EdgeInformation::Isotropic, "isotropic"},
                                      {EdgeInformation::Anisotropic, "anisotropic"}});

struct TrackerOptions : public mrpt::config::CLoadableOptions {
  /// Local Mapping's window and pool: section [local_map] (SlamOptions loads it; this struct's
  /// own load reads [tracker] alone).
  LocalMapOptions localMap;
  double ratioThreshold = 0.8;  ///< θ: multi-view ratio test
  int loopHopThreshold = 3;     ///< matched keyframes farther apart than this (R) close a loop
  int loopMinInliers = 10;      ///< a keyframe "matches" the frame with at least this many inliers
  int edgeMinMatches = 5;       ///< fewer inlier matches with a keyframe make no graph edge
  int minFeatures = 20;         ///< fewer features with depth: the frame cannot be tracked
  int relocalizeAfter = 1;      ///< lost frames before the whole map is searched as well
  int relocalizeMinInliers = 20;  ///< stricter than min_inliers: the whole map can alias
  /// Frames a session started from a saved map waits to relocalize in it (the map may not show
  /// this place) before it maps on its own: a new component of the map, not connected to the
  /// rest until place recognition joins them (0 = keep waiting). A camera that tracked and then
  /// lost its way keeps waiting to relocalize: its trajectory stays in one frame.
  int newComponentAfter = 30;
  /// Track and relocalize in a loaded map without changing it: no keyframe is added, so nothing
  /// is optimized and the map, the memory and the cost per frame stay as they are however long
  /// the session. A frame whose view the map covers less than keyframe_overlap (where mapping
  /// would add a keyframe) is reported outside the map. Needs a start map.
  bool localizationOnly = false;
  /// With localizationOnly: where the map covers too little of the view, add keyframes as
  /// mapping does; the loaded keyframes stay as they are (the optimizations hold them fixed).
  bool extendMap = false;
  double maxTranslationJump = 0.5;  ///< metres between consecutive tracked frames (not when lost)
  bool keepKeyframeImages = false;  ///< store colour+depth in keyframes for dense outputs
  bool weightedRefit = true;        ///< final pose fit weighs pairs by their depth noise
  EdgeInformation edgeInformation = EdgeInformation::Isotropic;  ///< how edges weigh matches
  /// For isotropic / anisotropic edge information: a keypoint's position is uncertain by this
  /// fraction of its detected size (SURF's coarse octaves localise to several pixels); 0 = one
  /// pixel for every keypoint.
  double keypointScaleSigma = 0;
  bool anisotropicRefinement = true;  ///< Gauss-Newton pose refinement with ray-aligned noise
  /// Dense point-to-plane term in the refinement; 0 = off (the paper, and the default: on
  /// quantized Kinect depth it biases the pose more than the features' registered points).
  double depthAlignmentWeight = 0.0;
  int depthAlignmentStride = 8;             ///< pixels between the current frame's depth samples
  double depthAlignmentMaxDistance = 0.05;  ///< metres: farther associations are rejected
  double depthAlignmentMaxDepth = 4.0;      ///< metres: farther depth is too noisy to align
  /// Reference normals from central differences instead of one-sided ones (docs/experiments.md).
  bool depthAlignmentCentralNormals = false;
  /// Keep the depth term's associations in graph edges for the bundle adjustment: worth it on
  /// precise depth only (docs/experiments.md).
  bool depthEdges = false;
  int depthEdgeMaxMatches = 400;  ///< per keyframe (thinned evenly, total weight kept)
  double depthEdgeWeight = 1.0;   ///< weight of those matches relative to feature matches
  /// When the features do not register a frame right after a tracked one, align its depth
  /// alone with the reference keyframe's (textureless scenes), see DepthOnlyRegistration.h.
  bool depthOnlyFallback = true;
  DepthOnlyOptions depthOnly;
  /// Rolling shutter and colour-depth time offset of the camera, undone with the predicted
  /// motion (SensorTiming.h); 0 = every pixel at the frame's time.
  SensorTimingOptions sensorTiming;
  /// With a rolling shutter or a depth offset: each frame's velocity is estimated with its pose
  /// (FrameVelocity) and moves its features' points, rather than the motion between frames
  /// extrapolated. That motion is its prior, give or take its own error: the poses' jitter over
  /// one frame interval, and what the extrapolation misses.
  bool estimateFrameVelocity = true;
  /// The prior's width: at most these (m/s, deg/s); a wider prior lets the velocity follow
  /// whatever else bends the points by row (lens distortion, depth timing).
  double velocityPriorSigmaMetres = 0.03;
  double velocityPriorSigmaDegrees = 6;
  /// Within that, the extrapolation's error measured over the last second (MotionModelError),
  /// but at least these: the measurement misses errors that persist over several frames.
  /// False: always the widths above.
  bool adaptiveVelocityPrior = true;
  double velocityPriorMinSigmaMetres = 0.005;
  double velocityPriorMinSigmaDegrees = 1;
  /// Learn the features' noise from the registered frames ([features] keypoint_*_sigma are the
  /// starting values), see KeypointNoiseEstimator.h.
  KeypointNoiseEstimatorOptions noiseEstimation;
  /// Learn the colour camera's rolling-shutter readout (rolling_shutter_ms is the starting
  /// value), see RollingShutterEstimator.h.
  RollingShutterEstimatorOptions rollingShutterEstimation;
  RansacOptions ransac;
  KeyframePolicyOptions keyframes;
  KeyframeCullingOptions culling;

  /// Its INI keys (section [tracker]; localMap has its own section), listed once for loading
  /// and saving.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("ratio_threshold", o.ratioThreshold);
    k("loop_hop_threshold", o.loopHopThreshold);
    k("loop_min_inliers", o.loopMinInliers);
    k("edge_min_matches", o.edgeMinMatches);
    k("min_features", o.minFeatures);
    k("relocalize_after", o.relocalizeAfter);
    k("relocalize_min_inliers", o.relocalizeMinInliers);
    k("new_component_after", o.newComponentAfter);
    k("localization_only", o.localizationOnly);
    k("extend_map", o.extendMap);
    k("max_translation_jump", o.maxTranslationJump);
    k("keep_keyframe_images", o.keepKeyframeImages);
    k("weighted_refit", o.weightedRefit);
    k("edge_information", o.edgeInformation);
    k("keypoint_scale_sigma", o.keypointScaleSigma);
    k("anisotropic_refinement", o.anisotropicRefinement);
    k("depth_alignment_weight", o.depthAlignmentWeight);
    k("depth_alignment_stride", o.depthAlignmentStride);
    k("depth_alignment_max_distance", o.depthAlignmentMaxDistance);
    k("depth_alignment_max_depth", o.depthAlignmentMaxDepth);
    k("depth_alignment_central_normals", o.depthAlignmentCentralNormals);
    k("depth_edges", o.depthEdges);
    k("depth_edge_max_matches", o.depthEdgeMaxMatches);
    k("depth_edge_weight", o.depthEdgeWeight);
    k("depth_only_fallback", o.depthOnlyFallback);
    k("estimate_keypoint_noise", o.noiseEstimation.enabled);
    k("estimate_rolling_shutter", o.rollingShutterEstimation.enabled);
    k("estimate_frame_velocity", o.estimateFrameVelocity);
    k("velocity_prior_sigma_m", o.velocityPriorSigmaMetres);
    k("velocity_prior_sigma_deg", o.velocityPriorSigmaDegrees);
    k("velocity_prior_adaptive", o.adaptiveVelocityPrior);
    k("velocity_prior_min_sigma_m", o.velocityPriorMinSigmaMetres);
    k("velocity_prior_min_sigma_deg", o.velocityPriorMinSigmaDegrees);
    DepthOnlyOptions::forEachKey(o.depthOnly, k);
    SensorTimingOptions::forEachKey(o.sensorTiming, k);
    RansacOptions::forEachKey(o.ransac, k);
    KeyframePolicyOptions::forEachKey(o.keyframes, k);
    k("keyframe_cull_share", o.culling.redundantShare);
    k("keyframe_cull_observers", o.culling.minObservers);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
};

}  // namespace slamdunk
