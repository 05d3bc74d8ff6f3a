#include <slamdunk/core/CameraIntrinsics.h>

#include <gtest/gtest.h>
#include <mrpt/img/TCamera.h>

#include <opencv2/calib3d.hpp>

using namespace slamdunk;

namespace {
CameraIntrinsics fr1() {
  CameraIntrinsics K;
  K.fx = 517.3;
  K.fy = 516.5;
  K.cx = 318.6;
  K.cy = 255.3;
  K.dist = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  return K;
}
}  // namespace

TEST(CameraIntrinsics, BackProjectIsPaperEquation2) {
  CameraIntrinsics K;
  const Eigen::Vector3d p = K.backProject(K.cx + K.fx, K.cy - 0.5 * K.fy, 2.0);
  EXPECT_NEAR(p.x(), 2.0, 1e-12);
  EXPECT_NEAR(p.y(), -1.0, 1e-12);
  EXPECT_NEAR(p.z(), 2.0, 1e-12);
  const Eigen::Vector2d uv = K.project(p);
  EXPECT_NEAR(uv.x(), K.cx + K.fx, 1e-9);
  EXPECT_NEAR(uv.y(), K.cy - 0.5 * K.fy, 1e-9);
}

TEST(CameraIntrinsics, UndistortAgreesWithOpenCV) {
  const CameraIntrinsics K = fr1();
  const cv::Matx33d cam(K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  const std::vector<double> dist(K.dist.begin(), K.dist.end());
  std::vector<cv::Point2d> raw{{10, 10}, {320, 240}, {600, 50}, {630, 470}, {100, 400}}, und;
  cv::undistortPoints(raw, und, cam, dist, cv::noArray(), cam,
                      cv::TermCriteria(cv::TermCriteria::COUNT, 10, 0));
  for (size_t i = 0; i < raw.size(); ++i) {
    const Eigen::Vector2d u = K.undistortPixel(raw[i].x, raw[i].y);
    EXPECT_NEAR(u.x(), und[i].x, 1e-6) << i;
    EXPECT_NEAR(u.y(), und[i].y, 1e-6) << i;
  }
}

TEST(CameraIntrinsics, TCameraRoundTrip) {
  const CameraIntrinsics K = fr1();
  const CameraIntrinsics back = CameraIntrinsics::fromTCamera(K.toTCamera());
  EXPECT_EQ(back.width, 640);
  EXPECT_DOUBLE_EQ(back.fx, K.fx);
  EXPECT_DOUBLE_EQ(back.cy, K.cy);
  for (size_t i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(back.dist[i], K.dist[i]);
  EXPECT_TRUE(back.hasDistortion());
  EXPECT_FALSE(CameraIntrinsics().hasDistortion());
}
