#pragma once
// The colour camera's rolling-shutter readout time, learned from the frames themselves. Most
// RGB-D cameras (Kinect, Xtion, RealSense colour) expose their rows one after another: a camera
// turning or moving fast sees the top and the bottom of the image from poses milliseconds
// apart, which bends the 3D points by millimetres to centimetres (SensorTiming undoes it, given
// the readout time). A global-shutter camera has none. The readout is one number per camera,
// rarely in its calibration: after each registered frame, the residuals of its inliers are
// asked how much of them a readout time would explain (a Gauss-Newton step in the readout with
// the frame's pose free), and the evidence of the frames in a sliding window is pooled into one
// estimate. Frames that hardly move carry no evidence and do not move it.

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/tracking/InlierSample.h>

#include <deque>
#include <vector>

namespace slamdunk {

struct RollingShutterEstimatorOptions {
  bool enabled = true;
  int window = 300;   ///< frames whose evidence is pooled
  double maxMs = 60;  ///< the estimate stays within [0, maxMs]
  /// Evidence needed before the estimate is used: its standard deviation below this (ms).
  double maxSigmaMs = 1.0;
  double huberSigmas = 3.0;  ///< residuals beyond this many σ weigh less (wrong matches)
};

class RollingShutterEstimator {
 public:
  RollingShutterEstimator(double initialMs, const RollingShutterEstimatorOptions& options);

  /// One registered frame: its inliers at `pose` (T_world_frame, in the samples' world), the
  /// camera's motion over the interval that ended at it (T_before_after) lasting `intervalMs`,
  /// the noise the inliers are weighed with, and the readout their points were corrected with.
  void addFrame(const std::vector<InlierSample>& inliers, const Pose& pose, const Pose& motion,
                double intervalMs, const DepthNoiseModel& noise, double appliedMs);
  /// The initial value until enough evidence was gathered, then the estimate.
  double readoutMs() const { return current_; }
  /// Whether readoutMs() is an estimate (enough evidence came), not the initial value.
  bool learned() const { return learned_; }
  /// Standard deviation of the pooled evidence (infinite before any).
  double sigmaMs() const;

 private:
  struct Evidence {
    double readoutMs;    ///< what this frame alone says
    double information;  ///< 1 / its variance (ms⁻²)
  };
  RollingShutterEstimatorOptions options_;
  double current_;
  bool learned_ = false;
  std::deque<Evidence> window_;
  double information_ = 0;  ///< summed over the window
};

}  // namespace slamdunk
