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
#include <slamdunk/tracking/PoseRefinement.h>

namespace slamdunk {

struct SensorTimingOptions {
  double rollingShutterMs = 0;   ///< colour readout: the bottom row is exposed this much later
  double depthTimeOffsetMs = 0;  ///< depth is captured this much after colour (mid-readout)

  bool any() const { return rollingShutterMs != 0 || depthTimeOffsetMs != 0; }

  /// Its INI keys (in [tracker]), listed once for IniSectionReader and IniSectionWriter.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("rolling_shutter_ms", o.rollingShutterMs);
    k("depth_time_offset_ms", o.depthTimeOffsetMs);
  }
};

class SensorTiming {
 public:
  explicit SensorTiming(const SensorTimingOptions& options) : options_(options) {}
  bool enabled() const { return options_.any(); }
  double rollingShutterMs() const { return options_.rollingShutterMs; }
  double depthTimeOffsetMs() const { return options_.depthTimeOffsetMs; }
  /// A keypoint's row as a fraction of the image height from its middle (-0.5 top, 0.5
  /// bottom): when a rolling shutter exposed it, in readouts from the frame's time.
  static double rowFraction(double row, double rows) { return (row + 0.5) / rows - 0.5; }
  /// A new readout time (RollingShutterEstimator learns it as frames come).
  void setRollingShutterMs(double ms) { options_.rollingShutterMs = ms; }

  /// Moves every feature's 3D point (and keeps its keypoint) into the camera frame at the
  /// frame's time, the camera moving by `motion` (T_before_after, in the camera frame) every
  /// `motionMs` milliseconds. Features whose depth cannot be read where the depth camera saw
  /// them keep their point.
  void compensate(FeatureSet& features, const RgbdFrame& frame, const Pose& motion,
                  double motionMs) const;
  /// The same with the camera's velocity.
  void compensate(FeatureSet& features, const RgbdFrame& frame, const Twist& velocity) const {
    // Any duration serves: 100 ms keeps a turn of up to 1800 deg/s within half a turn.
    compensate(features, frame, motion(velocity, 100.0), 100.0);
  }

  /// How a compensated feature point moves when the velocity it was compensated with changes
  /// (d point / d twist, first order): across its colour ray with its row's time, which chose
  /// the surface point, and along the ray with the depth image's time, which measured it.
  /// `row` is the keypoint's image row.
  Eigen::Matrix<double, 3, 6> velocityJacobian(const Eigen::Vector3d& point, double row,
                                               double rows) const;

  /// The camera's pose `fraction` of `motion`'s duration after the frame's time, relative to it
  /// (constant velocity: rotation angle and translation scaled by `fraction`).
  static Pose interpolate(const Pose& motion, double fraction);
  /// A motion over `ms` milliseconds as a constant velocity, and back.
  static Twist twist(const Pose& motion, double ms);
  static Pose motion(const Twist& velocity, double ms);

 private:
  SensorTimingOptions options_;
};

}  // namespace slamdunk
