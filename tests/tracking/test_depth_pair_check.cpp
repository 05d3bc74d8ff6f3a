// A trajectory checked against its depth images (checkDepthPair) on exact ray-cast depth seen
// through a lens with strong radial distortion: the true relative pose is confirmed, a pose
// turned too far is brought back, and the distortion is taken into account on both sides.

#include <slamdunk/tracking/DepthPairCheck.h>

#include "RenderPlanes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

using namespace slamdunk;

namespace {

/// A QVGA camera with a Kinect-like barrel distortion (TUM fr1's k1, k2).
CameraIntrinsics distortedCamera() {
  CameraIntrinsics K = test::centredCamera(320, 240, 260);
  K.dist = {0.26, -0.95, 0, 0, 0};
  return K;
}

/// The corner seen from `pose` through K's lens: each pixel's depth along its undistorted ray.
RgbdFrame frameAt(const Pose& pose) {
  const CameraIntrinsics K = distortedCamera();
  const auto planes = test::cornerPlanes();
  cv::Mat depth(K.height, K.width, CV_32F, cv::Scalar(0));
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      // The exact depth along this pixel's own ray, where the lens bends it from inside the view.
      const Eigen::Vector2d p = K.undistortPixel(u, v);
      if (p.x() < 0 || p.y() < 0 || p.x() > K.width - 1 || p.y() > K.height - 1) continue;
      const Eigen::Vector3d ray((p.x() - K.cx) / K.fx, (p.y() - K.cy) / K.fy, 1.0);
      depth.at<float>(v, u) = static_cast<float>(test::depthAlongRay(pose, ray, planes));
    }
  return RgbdFrame(0, cv::Mat(K.height, K.width, CV_8U, cv::Scalar(128)), depth, K);
}

}  // namespace

TEST(DepthPairCheck, ConfirmsTheTrueRelativePoseThroughADistortedLens) {
  const Pose source = poseFromAxisAngle({0.3, 1, 0.1}, 3 * kDeg, {0.05, -0.02, 0.03});
  const Pose target = poseFromAxisAngle({1, 0.2, 0}, -2 * kDeg, {-0.03, 0.01, 0.06});
  const Pose truth = target.inverse() * source;
  const DepthPairCheck c = checkDepthPair(frameAt(source), frameAt(target), truth);
  ASSERT_TRUE(c.aligned) << c.failure;
  EXPECT_LT(c.medianResidualGiven, 0.0005);
  EXPECT_LT(rotationDistance(c.alignedPose, truth), 0.03 * kDeg);
  EXPECT_LT(translationDistance(c.alignedPose, truth), 0.0005);
}

TEST(DepthPairCheck, BringsBackARelativePoseTurnedTooFar) {
  const Pose source = poseFromAxisAngle({0.3, 1, 0.1}, 3 * kDeg, {0.05, -0.02, 0.03});
  const Pose target = Pose::Identity();
  const Pose truth = target.inverse() * source;
  // The trajectory turns 1.5 degrees further about the camera's y axis than the camera did.
  const Pose given = poseFromAxisAngle({0, 1, 0}, 1.5 * kDeg, Eigen::Vector3d::Zero()) * truth;
  const DepthPairCheck c = checkDepthPair(frameAt(source), frameAt(target), given);
  ASSERT_TRUE(c.aligned) << c.failure;
  EXPECT_GT(c.medianResidualGiven, 0.005);
  EXPECT_LT(c.medianResidualAligned, 0.0005);
  EXPECT_LT(rotationDistance(c.alignedPose, truth), 0.05 * kDeg);
  EXPECT_LT(translationDistance(c.alignedPose, truth), 0.001);
}
