#pragma once
// Synthetic RGB-D sequences with exact ground truth: SyntheticScene rendered by
// SyntheticRenderer along a SyntheticTrajectory, as CObservation3DRangeScan observations laid
// out exactly like tum2rawlog's (raw 16-bit depth, rangeUnits = 1/5000, range_is_depth, BGR
// colour, identical pinhole intrinsics for both cameras), so the pipeline treats both alike.
// The camera poses go to a TUM ground-truth file (optical frame T_w_opt, same timestamps).

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/synthetic/SyntheticTrajectory.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <opencv2/core.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace slamdunk {

class SyntheticScene;
class SyntheticRenderer;

struct SyntheticOptions {
  /// See SyntheticTrajectory::names(); the trajectory also chooses the scene
  /// (SyntheticTrajectory::sceneOf: "room" for sweep and loop, "office" for tour).
  std::string trajectory = "loop";
  int frames = 0;  ///< 0 = the trajectory's default count
  /// Only the first N of those frames (0 = all): the start of a long path at its own speed,
  /// e.g. 20 s of the 2.5-minute scan for a short test.
  int firstFrames = 0;
  /// Leaves out the path's first N frames (before firstFrames counts): a sequence that starts
  /// partway, its frames identical to the whole path's and stamped as there (two sessions of
  /// one walk share one ground truth).
  int skipFrames = 0;
  unsigned seed = 1;  ///< selects the textures (and the depth noise)
  int width = 640, height = 480;
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5;
  /// The observations state focal lengths this many percent larger than the ones rendered with:
  /// a camera known by its model's nominal intrinsics, not its own calibration (0 = exact).
  double statedFocalErrorPercent = 0;
  double depthNoiseSigma = 0;  ///< metres; Gaussian noise added to valid depth (0 = exact)
  /// Simulate a Kinect v1's depth (structured-light disparity: lateral jitter, disparity noise,
  /// 1/8-pixel quantisation) instead of exact depth; see kinectDepth().
  bool kinectDepth = false;
  /// Hand-held camera effects on the colour image, each off at 0 / false. Frame i's ground-truth
  /// pose is the colour camera's at the middle of its exposure and readout.
  double exposureMs = 0;  ///< motion blur: colour integrates the image over this exposure time
  double rollingShutterMs = 0;   ///< row readout: the bottom row is exposed this much after the top
  bool autoExposure = false;     ///< a changing gain (exposureGain()), saturating at white
  double depthTimeOffsetMs = 0;  ///< depth is captured this much after colour (may be negative)
  /// Renders per frame for blur / rolling shutter (0 = enough for 1.5 px of image motion between
  /// two; with blur, supersampling 1 is usually enough: the renders average anyway).
  int motionSamples = 0;
  bool externalImages = false;  ///< writeSyntheticSequence: images in <name>_Images/
  /// With externalImages: colour as JPEG of this quality (1-100) instead of PNG (0, lossless).
  int jpegQuality = 0;
  int supersampling = 3;  ///< colour anti-aliasing factor (odd), see SyntheticRenderer
  bool ceiling = true;
  /// The office's room C a copy of room A (FloorPlan::officeWithTwinRooms): 'tour' only.
  bool twinRooms = false;
  /// The office's corridor from B to C painted almost plain (FloorPlan::withBareArea with
  /// kBareCorridorDetail): a 7 m stretch of the tour with few features. 'tour' only.
  bool bareCorridor = false;
  static constexpr double kBareCorridorDetail = 0.02;

  CameraIntrinsics intrinsics() const;        ///< the rendering's (the true camera)
  CameraIntrinsics statedIntrinsics() const;  ///< what the observations say (see above)
  bool motionEffects() const { return exposureMs > 0 || rollingShutterMs > 0; }
  /// The hand-held preset: 10 ms exposure, 20 ms rolling shutter, auto exposure and depth 5 ms
  /// after colour (a Kinect v1 / Xtion-like camera, whose streams are not synchronised).
  void enableHandHeldEffects();
  /// Throws std::invalid_argument naming the first bad option.
  void validate() const;
};

/// Depth a Kinect v1 would measure of a scene whose exact z-depth (CV_32F metres, 0 = none) is
/// given: each pixel's pattern lands 0.5 px (σ) off, disparity gets Gaussian noise and 1/8-px
/// quantisation. Deterministic for a seed.
cv::Mat kinectDepth(const cv::Mat& exact, double fx, uint64_t seed);

/// Renders frames of one sequence on demand, in any order; frame i depends only on the options
/// and i. Creates one offscreen OpenGL context: use it from one thread.
class SyntheticSequence {
 public:
  static constexpr const char* kSensorLabel = "SYNTH_RGBD";
  static constexpr double kDepthFactor = 5000.0;  ///< raw depth units per metre (TUM)

  /// Validates the options, builds the trajectory's scene and the renderer. Throws
  /// std::invalid_argument for bad options, std::runtime_error when no OpenGL context is available.
  explicit SyntheticSequence(const SyntheticOptions& options);
  ~SyntheticSequence();

  size_t size() const { return groundTruth_.size(); }
  /// T_w_opt and timestamp of every frame.
  const Trajectory& groundTruth() const { return groundTruth_; }
  const SyntheticOptions& options() const { return options_; }
  const SyntheticScene& scene() const { return *scene_; }

  /// The auto-exposure gain applied to the colour of the path's frame i (skipped frames count;
  /// 1 without autoExposure): a slow random-looking drift between about 0.6 and 1.5, seeded.
  double exposureGain(size_t i) const;

  /// Frame i as an observation (colour and depth in memory). With kinectTwin (only for a
  /// sequence without kinectDepth), also the same frame as the sequence with kinectDepth on
  /// renders it: identical colour, Kinect-like depth, from one render.
  mrpt::obs::CObservation3DRangeScan::Ptr renderFrame(
      size_t i, mrpt::obs::CObservation3DRangeScan::Ptr* kinectTwin = nullptr);
  /// Frame i as images: BGR CV_8UC3 and z-depth CV_32F metres (already quantised to 1/5000 m
  /// and noisy exactly as in the observation).
  void renderImages(size_t i, cv::Mat& bgr, cv::Mat& depthMetres);

 private:
  void renderRaw(size_t i, cv::Mat& bgr, cv::Mat& depthRaw, cv::Mat* kinectTwinDepthRaw = nullptr);
  /// Raw depth (CV_16U) the sensor reports of frame i's exact depth: Kinect-like or exact, plus
  /// the optional Gaussian noise.
  cv::Mat measuredDepth(size_t i, const cv::Mat& exactDepth, bool kinect) const;
  mrpt::obs::CObservation3DRangeScan::Ptr observation(size_t i, const cv::Mat& bgr,
                                                      const cv::Mat& depthRaw) const;
  /// Colour exposed over time: blur and rolling shutter from renders at sub-frame poses.
  cv::Mat renderMotion(size_t i);
  /// Largest image motion (px) of scene points 2 m away between two (fractional) frames.
  double imageMotion(double fromFrame, double toFrame) const;
  SyntheticOptions options_;
  Trajectory groundTruth_;
  SyntheticTrajectory::PoseAtFrame poseAt_;
  std::unique_ptr<SyntheticScene> scene_;
  std::unique_ptr<SyntheticRenderer> renderer_;
};

using ProgressCallback = std::function<void(size_t done, size_t total)>;

/// Renders the whole sequence in memory (for tests; a 400-frame VGA sequence takes ~600 MB).
std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> renderSyntheticSequence(
    const SyntheticOptions& options, Trajectory* groundTruthOut,
    const ProgressCallback& progress = {});

struct SyntheticSequenceSummary {
  size_t frames = 0;
  std::string scene;  ///< FloorPlan name
  TrajectoryStats stats;
  std::string rawlogPath, groundTruthPath, imagesFolder;
  std::string kinectTwinRawlogPath, kinectTwinGroundTruthPath;  ///< empty without a twin
  double renderSeconds = 0;  ///< wall time spent rendering (all frames)
};

/// "<rawlog without .rawlog>_groundtruth.txt"
std::string defaultSyntheticGroundTruthPath(const std::string& rawlogPath);

/// Renders frame by frame into rawlogPath (observation-only format) and writes the ground truth
/// (TUM, optical frame) to groundTruthPath (empty = default path). Existing files are replaced
/// only when everything succeeded. With options.externalImages, colour PNGs and MRPT external
/// depth matrices go to "<dir>/<name>_Images/" (also swapped in only on success).
/// kinectTwinRawlogPath (non-empty, options without kinectDepth): also writes the sequence that
/// options with kinectDepth on would give, byte for byte, there (ground truth at its default
/// path), rendering each frame once for both: the exact- and Kinect-depth pair in half the time.
SyntheticSequenceSummary writeSyntheticSequence(const SyntheticOptions& options,
                                                const std::string& rawlogPath,
                                                const std::string& groundTruthPath = {},
                                                const ProgressCallback& progress = {},
                                                const std::string& kinectTwinRawlogPath = {});

}  // namespace slamdunk
