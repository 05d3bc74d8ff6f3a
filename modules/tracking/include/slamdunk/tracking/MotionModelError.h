#pragma once
// How far off the motion model's velocity has been over the last frames: the width of the
// prior that each frame's velocity is estimated with (Tracker, FrameVelocity).
//
// The model extrapolates the motion between the last frames to the new frame's time. Once the
// next frame is tracked, the velocity at that frame is known better (the central difference of
// the poses on either side of it), and the difference is the model's error. Smooth motion with
// precise poses is predicted to about a degree per second; a shaking hand, or the jittery poses
// of a real Kinect, to several. One fixed width cannot serve both: too wide where the model is
// good, and the velocity follows the errors of the map the frame is matched against (its
// keyframes then store them, and the rolling-shutter readout learned against the map drifts);
// too narrow where the model is poor, and a hand that really shakes is held back.

#include <slamdunk/tracking/PoseRefinement.h>

#include <deque>
#include <optional>

namespace slamdunk {

class MotionModelError {
 public:
  /// `window`: frames remembered; `minSamples`: how many before sigma() answers.
  MotionModelError(int window, int minSamples);

  /// The velocity the model predicted at a frame, and the one measured there afterwards (both
  /// in the frame's camera, translation then rotation, per second).
  void add(const Twist& predicted, const Twist& measured);
  /// Root-mean-square error per axis over the window, one value for the three translation axes
  /// (m/s) and one for the three rotation axes (rad/s); none before `minSamples` errors.
  std::optional<Twist> sigma() const;
  size_t samples() const { return errors_.size(); }

 private:
  size_t window_;
  size_t minSamples_;
  std::deque<Twist> errors_;
};

}  // namespace slamdunk
