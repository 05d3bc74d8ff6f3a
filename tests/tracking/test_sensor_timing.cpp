// SensorTiming: a camera turning at 90 deg/s in front of a wall, with a 20 ms rolling shutter and
// depth taken 5 ms after colour. Each feature's 3D point, read naively at its pixel, is off by
// centimetres; compensated with the camera's motion, it is where the wall really is in the
// camera frame at the frame's time.

#include <slamdunk/tracking/SensorTiming.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace slamdunk;

namespace {

constexpr double kRate = 90 * kDeg;  // rad/s, about the vertical (optical y) axis
constexpr double kWall = 2.0;        // world z of the wall

Pose yaw(double angle) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return T;
}

/// World point of the wall on the ray through pixel (u, v) of a camera at `cameraYaw`.
Eigen::Vector3d wallPoint(const CameraIntrinsics& K, double u, double v, double cameraYaw) {
  const Eigen::Vector3d d =
      yaw(cameraYaw).linear() * Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
  return d * (kWall / d.z());
}

}  // namespace

TEST(SensorTiming, RollingShutterAndDepthOffsetAreUndone) {
  CameraIntrinsics K;  // 640 x 480, 525 px
  const double rollingShutterMs = 20, depthOffsetMs = 5, periodMs = 1000.0 / 30;
  // Depth image of the frame at time 0, captured 5 ms later: z along each pixel's ray.
  cv::Mat depth(K.height, K.width, CV_32F);
  const double depthYaw = kRate * depthOffsetMs / 1000;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u)
      depth.at<float>(v, u) =
          static_cast<float>((yaw(depthYaw).inverse() * wallPoint(K, u, v, depthYaw)).z());
  const RgbdFrame frame(0.0, cv::Mat(K.height, K.width, CV_8U, cv::Scalar(128)), depth, K);

  // Features as the extractor makes them: the depth read at the colour pixel.
  FeatureSet features;
  std::vector<Eigen::Vector3d> truth;
  for (const double v : {12.0, 240.0, 470.0})
    for (const double u : {60.0, 320.0, 580.0}) {
      features.keypoints.emplace_back(cv::Point2f(float(u), float(v)), 10.f);
      features.points.push_back(*frame.backProject(u, v));
      // The colour row was exposed at its own time; the true point in the camera frame at 0.
      const double rowTime = ((v + 0.5) / K.height - 0.5) * rollingShutterMs / 1000;
      truth.push_back(wallPoint(K, u, v, kRate * rowTime));
    }
  features.descriptors = cv::Mat::zeros(int(features.size()), 64, CV_32F);

  double naive = 0;
  for (size_t i = 0; i < truth.size(); ++i)
    naive = std::max(naive, (features.points[i] - truth[i]).norm());
  SensorTiming timing({rollingShutterMs, depthOffsetMs});
  const Pose motionPerFrame = yaw(kRate * periodMs / 1000);  // T_previous_current
  timing.compensate(features, frame, motionPerFrame, periodMs);
  double compensated = 0;
  for (size_t i = 0; i < truth.size(); ++i)
    compensated = std::max(compensated, (features.points[i] - truth[i]).norm());
  std::printf("[ sensor timing ] largest point error: naive %.1f mm, compensated %.2f mm\n",
              naive * 1000, compensated * 1000);
  EXPECT_GT(naive, 0.02);
  EXPECT_LT(compensated, 0.002);
}

TEST(SensorTiming, NothingToDoWithoutTimingOrMotion) {
  CameraIntrinsics K;
  const RgbdFrame frame(0.0, cv::Mat(K.height, K.width, CV_8U, cv::Scalar(128)),
                        cv::Mat(K.height, K.width, CV_32F, cv::Scalar(2.0f)), K);
  FeatureSet features;
  features.keypoints.emplace_back(cv::Point2f(10, 10), 10.f);
  features.points.push_back(*frame.backProject(10, 10));
  const Eigen::Vector3d before = features.points[0];
  SensorTiming({}).compensate(features, frame, yaw(0.05), 33.3);
  EXPECT_EQ(features.points[0], before);
  SensorTiming({20, 5}).compensate(features, frame, Pose::Identity(), 33.3);  // standing still
  EXPECT_LT((features.points[0] - before).norm(), 1e-9);
  // Interpolation: half the angle and half the translation.
  Pose m = yaw(0.2);
  m.translation() = Eigen::Vector3d(0.1, 0, 0);
  const Pose half = SensorTiming::interpolate(m, 0.5);
  EXPECT_NEAR(Eigen::AngleAxisd(half.linear()).angle(), 0.1, 1e-12);
  EXPECT_NEAR(half.translation().x(), 0.05, 1e-12);
}
