#pragma once
// How precisely this camera's features are measured, learned from the frames themselves. The
// features are weighed by a noise model (a keypoint's pixel error, and the error of the depth
// read there, growing with z²) in the pose refinement, the graph edges and the bundle
// adjustment. Its right values differ by an order of magnitude between sensors: an exact
// synthetic renderer, a Kinect with registered depth, a Kinect whose depth is captured a few
// milliseconds off the colour image. After each registered frame the residuals of its inliers
// (frame point against map point, at the refined pose) are split into their part across the
// viewing ray (pixels) and along it (depth); robust per-frame estimates are kept over a sliding
// window, and their medians are the model the next frames and optimizations use.

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/tracking/InlierSample.h>

#include <deque>
#include <vector>

namespace slamdunk {

struct KeypointNoiseEstimatorOptions {
  bool enabled = true;
  int window = 60;      ///< frames whose estimates are kept
  int minFrames = 10;   ///< the prior is used until this many frames were measured
  int minSamples = 20;  ///< fewer inliers: the frame is not measured
  double minPixelSigma = 0.05, maxPixelSigma = 5.0;
  double minDepthSigma = 1e-5, maxDepthSigma = 0.05;  ///< m at 1 m
};

class KeypointNoiseEstimator {
 public:
  KeypointNoiseEstimator(const DepthNoiseModel& prior, const KeypointNoiseEstimatorOptions& o);

  /// Measures one registered frame: `pose` is T_world_frame.
  void addFrame(const std::vector<InlierSample>& inliers, const Pose& pose);
  /// The prior until enough frames were measured (or when disabled), then the estimate.
  const DepthNoiseModel& current() const { return current_; }
  /// Frames measured so far (those with enough inliers).
  size_t framesMeasured() const { return measured_; }

 private:
  DepthNoiseModel prior_, current_;
  KeypointNoiseEstimatorOptions options_;
  std::deque<double> pixelSigmas_, depthSigmas_;
  size_t measured_ = 0;
};

}  // namespace slamdunk
