#pragma once
// Camera Tracking's parameters: section [tracker] (paper Table 3 names in comments).

#include <slamdunk/tracking/DepthOnlyRegistration.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/tracking/KeyframePolicy.h>
#include <slamdunk/tracking/KeypointNoiseEstimator.h>
#include <slamdunk/mapping/LocalMap.h>
#include <slamdunk/tracking/RansacAbsoluteOrientation.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>
#include <slamdunk/tracking/SensorTiming.h>

#include <mrpt/config/CLoadableOptions.h>

namespace slamdunk {

/// How graph edges weigh their matches: the paper's w = 1 - θ' alone, or also by the depth
/// noise of the two points, as a scalar or as a ray-aligned (anisotropic) information matrix.
enum class EdgeInformation { Paper, Isotropic, Anisotropic };
EdgeInformation edgeInformationFromString(const std::string& name);
std::string toString(EdgeInformation e);

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
  int relocalizeMinInliers = 20;    ///< stricter than min_inliers: the whole map can alias
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
  FeaturePoolOptions pool;
  RansacOptions ransac;
  KeyframePolicyOptions keyframes;

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
};

}  // namespace slamdunk
