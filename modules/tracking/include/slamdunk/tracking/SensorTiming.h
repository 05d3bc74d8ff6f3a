#pragma once
// When an RGB-D camera's pixels are not all captured at the frame's time: a rolling-shutter
// colour camera exposes its rows one after another, and the depth image may be taken a few
// milliseconds before or after the colour one. A moving camera then sees each feature from a
// slightly different pose: on fast hand-held turns this bends the 3D points by centimetres and
// the pose estimates with them. Given the camera's motion over one frame (the tracker's
// constant-velocity prediction), each feature's 3D point is moved into the camera frame at the
// frame's time: its depth is read where the depth camera saw that point, and the point is
// carried from the depth camera's instant to the frame's.

#include <slamdunk/core/Pose.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/features/FeatureExtractor.h>

namespace slamdunk {

struct SensorTimingOptions {
  double rollingShutterMs = 0;   ///< colour readout: the bottom row is exposed this much later
  double depthTimeOffsetMs = 0;  ///< depth is captured this much after colour (mid-readout)

  bool any() const { return rollingShutterMs != 0 || depthTimeOffsetMs != 0; }
};

class SensorTiming {
 public:
  explicit SensorTiming(const SensorTimingOptions& options) : options_(options) {}
  bool enabled() const { return options_.any(); }
  double rollingShutterMs() const { return options_.rollingShutterMs; }
  /// A new readout time (RollingShutterEstimator learns it as frames come).
  void setRollingShutterMs(double ms) { options_.rollingShutterMs = ms; }

  /// Moves every feature's 3D point (and keeps its keypoint) into the camera frame at the
  /// frame's time, the camera moving by `motion` (T_before_after, in the camera frame) every
  /// `motionMs` milliseconds. Features whose depth cannot be read where the depth camera saw
  /// them keep their point.
  void compensate(FeatureSet& features, const RgbdFrame& frame, const Pose& motion,
                  double motionMs) const;

  /// The camera's pose `fraction` of `motion`'s duration after the frame's time, relative to it
  /// (constant velocity: rotation angle and translation scaled by `fraction`).
  static Pose interpolate(const Pose& motion, double fraction);

 private:
  SensorTimingOptions options_;
};

}  // namespace slamdunk
