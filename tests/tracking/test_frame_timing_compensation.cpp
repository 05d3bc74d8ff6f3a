// FrameTimingCompensation's motion model: a camera tracked at a constant velocity has that
// velocity predicted for the next frame (the one its points are undone with), and nothing is
// predicted where no motion is known (the map's first frame, a global-shutter camera).

#include <slamdunk/tracking/FrameTimingCompensation.h>

#include "RenderPlanes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace slamdunk;

namespace {

constexpr double kFrameSeconds = 1.0 / 30;

/// A small camera: 64x48 pixels.
CameraIntrinsics smallCamera() { return test::centredCamera(64, 48, 60); }

/// A frame of a wall `depth` metres ahead (none for 0).
RgbdFrame frameAt(double timestamp, float depth = 0) {
  return RgbdFrame(timestamp, cv::Mat(48, 64, CV_8U, cv::Scalar(0)),
                   cv::Mat(48, 64, CV_32F, cv::Scalar(depth)), smallCamera());
}

/// One feature at the bottom row, on that wall.
FeatureSet featureAtTheBottom(double depth) {
  FeatureSet f;
  f.keypoints.emplace_back(cv::Point2f(32, 47), 10.f);
  f.points.push_back(smallCamera().backProject(32, 47, depth));
  f.descriptors = cv::Mat(1, 64, CV_32F, cv::Scalar(0));
  return f;
}

/// v = 0.3 m/s along x and 20 deg/s about y, as a motion over one frame.
Twist constantVelocity() {
  Twist v;
  v << 0.3, 0, 0, 0, 20 * M_PI / 180, 0;
  return v;
}

TrackerOptions withRollingShutter(double ms) {
  TrackerOptions o;
  o.sensorTiming.rollingShutterMs = ms;
  return o;
}

/// Tracks `frames` frames moving at constant velocity (none registered by features, so the
/// prediction comes from the poses alone); returns the last pose.
Pose trackConstantMotion(FrameTimingCompensation& timing, int frames) {
  const Pose step = SensorTiming::motion(constantVelocity(), 1000 * kFrameSeconds);
  Pose pose = Pose::Identity();
  for (int i = 1; i <= frames; ++i) {
    FeatureSet none;
    timing.beginFrame(frameAt(i * kFrameSeconds), none, pose, false);
    pose = pose * step;
    timing.endFrame(pose, false);
  }
  return pose;
}

}  // namespace

TEST(FrameTimingCompensation, PredictsTheVelocityOfAConstantMotion) {
  const TrackerOptions options = withRollingShutter(20);
  FrameTimingCompensation timing(options, std::make_shared<KeyframeGraph>());
  const Pose last = trackConstantMotion(timing, 3);

  FeatureSet none;
  timing.beginFrame(frameAt(4 * kFrameSeconds), none, last, false);
  const FrameVelocity* v = timing.velocityToEstimate();
  ASSERT_NE(v, nullptr);
  EXPECT_LT((v->compensated - constantVelocity()).norm(), 1e-9);
  EXPECT_LT((v->prior - constantVelocity()).norm(), 1e-9);
  ASSERT_TRUE(timing.lastMotion());
  EXPECT_LT(translationDistance(*timing.lastMotion(),
                                SensorTiming::motion(constantVelocity(), 1000 * kFrameSeconds)),
            1e-12);
}

TEST(FrameTimingCompensation, UndoesTheRollingShutterOfAMovingCamera) {
  const TrackerOptions options = withRollingShutter(20);
  FrameTimingCompensation timing(options, std::make_shared<KeyframeGraph>());
  const Pose last = trackConstantMotion(timing, 3);

  // A feature at the bottom row was exposed 10 ms after the frame's time: the camera had moved
  // on by then, and its point is carried back to the frame's time.
  FeatureSet features = featureAtTheBottom(2.0);
  const Eigen::Vector3d measured = features.points[0];
  timing.beginFrame(frameAt(4 * kFrameSeconds, 2.0f), features, last, false);
  EXPECT_GT((features.points[0] - measured).norm(), 1e-3);
}

TEST(FrameTimingCompensation, PredictsNothingWithoutAKnownMotion) {
  const TrackerOptions options = withRollingShutter(20);
  FrameTimingCompensation timing(options, std::make_shared<KeyframeGraph>());
  FeatureSet none;
  timing.beginFrame(frameAt(0), none, Pose::Identity(), false);
  EXPECT_EQ(timing.velocityToEstimate(), nullptr);  // the first frame
  timing.mapStarted(0, frameAt(0), none);
  timing.beginFrame(frameAt(kFrameSeconds), none, Pose::Identity(), false);
  EXPECT_EQ(timing.velocityToEstimate(), nullptr);  // its keyframe is not in this map
}

TEST(FrameTimingCompensation, AGlobalShutterCameraIsLeftAlone) {
  const TrackerOptions options;  // no rolling shutter, no depth offset
  FrameTimingCompensation timing(options, std::make_shared<KeyframeGraph>());
  const Pose last = trackConstantMotion(timing, 3);
  FeatureSet features = featureAtTheBottom(2.0);
  const Eigen::Vector3d measured = features.points[0];
  timing.beginFrame(frameAt(4 * kFrameSeconds, 2.0f), features, last, false);
  EXPECT_EQ(timing.velocityToEstimate(), nullptr);
  EXPECT_EQ(features.points[0], measured);
  EXPECT_EQ(timing.rollingShutterMs(), 0);
}
