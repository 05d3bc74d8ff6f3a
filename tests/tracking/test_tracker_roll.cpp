// A camera turning about its optical axis. Upright SURF describes a rolled view's features
// rolled with it, and past about 20 degrees they no longer match the map's: without turning its
// descriptors ([features] surf_roll_limit_deg = 0) the tracker makes keyframe after keyframe
// (by the paper's rule: the covered-view rule would hide the lost matches).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/tracking/Tracker.h>

#include "../common/TestData.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include <cmath>

using namespace slamdunk;

namespace {

/// What the frame's camera sees rolled by `degrees` about its optical axis (fx = fy and no
/// distortion: the image turns about the principal point), within a disc about that point, so
/// that every roll sees the same part of the scene.
RgbdFrame rolled(const RgbdFrame& frame, double degrees, double timestamp) {
  const CameraIntrinsics& K = frame.intrinsics();
  const cv::Point2f centre(static_cast<float>(K.cx), static_cast<float>(K.cy));
  // A camera turned clockwise on the image (about +z, y down) sees the scene turn the other way.
  const cv::Matx23d turn = cv::getRotationMatrix2D(centre, degrees, 1.0);
  cv::Mat grey, depth;
  cv::warpAffine(frame.grey(), grey, turn, frame.grey().size(), cv::INTER_LINEAR);
  cv::warpAffine(frame.depth(), depth, turn, frame.depth().size(), cv::INTER_NEAREST);
  cv::Mat outside(grey.size(), CV_8U, cv::Scalar(255));
  cv::circle(outside, centre, std::min(grey.rows, grey.cols) / 2 - 4, cv::Scalar(0), cv::FILLED);
  grey.setTo(0, outside);
  depth.setTo(0, outside);
  return RgbdFrame(timestamp, grey, depth, K);
}

struct RollRun {
  size_t tracked = 0;
  size_t keyframes = 0;
  double worstRotationErrorDeg = 0;
};

/// Rolls the camera from 0 to 60 degrees, 6 degrees a frame, tracking each view.
RollRun rollThrough(const RgbdFrame& first, double rollLimitDeg) {
  FeatureOptions features;
  features.surfRollLimitDeg = rollLimitDeg;
  // The paper's keyframe rule, which makes a keyframe wherever the matches fail: with the
  // covered-view rule a rolled view of the same place never makes one, matched or not.
  TrackerOptions options;
  options.keyframes.coveredView = 0;
  Tracker tracker(options, features, std::make_shared<KeyframeGraph>());
  RollRun run;
  for (int step = 0; step <= 10; ++step) {
    const double degrees = 6.0 * step;
    const TrackingResult r = tracker.process(rolled(first, degrees, step / 30.0));
    if (r.status == TrackingStatus::Lost) continue;
    ++run.tracked;
    Pose expected = Pose::Identity();
    expected.linear() =
        Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    run.worstRotationErrorDeg =
        std::max(run.worstRotationErrorDeg, rotationDistance(r.pose, expected) * 180.0 / M_PI);
  }
  run.keyframes = tracker.graph()->keyframeCount();
  return run;
}

}  // namespace

TEST(Tracker, ARollingCameraKeepsMatchingItsKeyframe) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  RawlogReader reader(rawlog);
  const auto observation = reader.next();
  ASSERT_TRUE(observation);
  const RgbdFrame first = RgbdFrame::fromObservation(*observation);

  const RollRun turned = rollThrough(first, FeatureOptions{}.surfRollLimitDeg);
  const RollRun upright = rollThrough(first, 0);
  std::printf("rolled 0-60 degrees: %zu keyframes turned, %zu upright\n", turned.keyframes,
              upright.keyframes);
  EXPECT_EQ(turned.tracked, 11u);
  EXPECT_LT(turned.worstRotationErrorDeg, 0.5);
  EXPECT_LE(turned.keyframes, 2u);
  EXPECT_GT(upright.keyframes, turned.keyframes + 1);
}
