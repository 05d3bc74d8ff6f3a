#include <slamdunk/core/DepthBackProjection.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace slamdunk;

namespace {

struct Point {
  int u, v;
  Eigen::Vector3d p;
};

std::vector<Point> pointsOf(const cv::Mat& depth, const CameraIntrinsics& K,
                            const DepthSampling& sampling, float minDepth = 0.0f) {
  std::vector<Point> out;
  forEachDepthPoint(
      depth, K, sampling, [&](float z) { return z > minDepth; },
      [&](int u, int v, const Eigen::Vector3d& p) {
        out.push_back({u, v, p});
      });
  return out;
}

CameraIntrinsics camera() {
  CameraIntrinsics K;  // 640x480, f = 525, principal point (319.5, 239.5)
  K.cx = 320;
  K.cy = 240;
  return K;
}

}  // namespace

TEST(DepthBackProjection, APixelGoesToItsPointOnTheRay) {
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0));
  depth.at<float>(240, 320) = 2.0f;  // the principal point
  depth.at<float>(345, 525) = 1.5f;  // 205 px right of it, 105 px down
  const auto points = pointsOf(depth, camera(), {});
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].u, 320);
  EXPECT_EQ(points[0].v, 240);
  EXPECT_EQ(points[0].p, Eigen::Vector3d(0, 0, 2));
  EXPECT_EQ(points[1].u, 525);
  EXPECT_EQ(points[1].v, 345);
  EXPECT_NEAR(points[1].p.x(), 205 * 1.5 / 525, 1e-12);  // 0.585714...
  EXPECT_NEAR(points[1].p.y(), 105 * 1.5 / 525, 1e-12);  // 0.3
  EXPECT_EQ(points[1].p.z(), 1.5);
}

TEST(DepthBackProjection, TheCallerDecidesWhichDepthsAreReadings) {
  cv::Mat depth(2, 3, CV_32F, cv::Scalar(1.0f));
  depth.at<float>(0, 1) = 0.0f;
  depth.at<float>(1, 0) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(1, 2) = 0.2f;
  const auto points = pointsOf(depth, camera(), {}, 0.5f);
  ASSERT_EQ(points.size(), 3u);  // row by row: (0,0), (2,0), (1,1)
  EXPECT_EQ(points[0].u, 0);
  EXPECT_EQ(points[1].u, 2);
  EXPECT_EQ(points[2].u, 1);
  EXPECT_EQ(points[2].v, 1);
}

TEST(DepthBackProjection, StepAndSubsampledDepthGiveFullImagePixels) {
  // A depth subsampled by 4 (80x60 for a 640x480 camera), every second sample taken.
  cv::Mat small(60, 80, CV_32F, cv::Scalar(1.0f));
  const auto points = pointsOf(small, camera(), {2, 4, false});
  ASSERT_EQ(points.size(), 30u * 40u);
  EXPECT_EQ(points[1].u, 8);  // sample (2, 0) is pixel (8, 0) of the full image
  EXPECT_EQ(points[1].v, 0);
  EXPECT_EQ(points[40].v, 8);
  EXPECT_NEAR(points[1].p.x(), (8 - 320) / 525.0, 1e-12);
  EXPECT_NEAR(points[1].p.y(), (0 - 240) / 525.0, 1e-12);
}

TEST(DepthBackProjection, UndistortsWhenAskedAndTheLensHasDistortion) {
  CameraIntrinsics K = camera();
  K.dist = {0.2, -0.5, 0, 0, 0};
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0));
  depth.at<float>(20, 30) = 2.0f;
  const Eigen::Vector2d und = K.undistortPixel(30, 20);
  const auto raw = pointsOf(depth, K, {1, 1, false});
  const auto undistorted = pointsOf(depth, K, {1, 1, true});
  ASSERT_EQ(raw.size(), 1u);
  ASSERT_EQ(undistorted.size(), 1u);
  EXPECT_EQ(raw[0].p, K.backProject(30, 20, 2.0));
  EXPECT_EQ(undistorted[0].p, K.backProject(und.x(), und.y(), 2.0));
  EXPECT_GT((raw[0].p - undistorted[0].p).norm(), 0.01);
}

TEST(DepthBackProjection, RejectsDepthThatIsNotMetresAsFloats) {
  const cv::Mat depth(4, 4, CV_16U, cv::Scalar(1000));
  EXPECT_THROW(pointsOf(depth, camera(), {}), std::invalid_argument);
  EXPECT_TRUE(pointsOf(cv::Mat(), camera(), {}).empty());
}

TEST(DepthBackProjection, ColourOfBgrAndGreyPixels) {
  cv::Mat bgr(2, 2, CV_8UC3, cv::Scalar(10, 20, 30));
  const auto rgb = rgbAt(bgr, 1, 1);
  ASSERT_TRUE(rgb);
  EXPECT_EQ(*rgb, (std::array<uint8_t, 3>{30, 20, 10}));
  const cv::Mat grey(2, 2, CV_8UC1, cv::Scalar(77));
  EXPECT_EQ(*rgbAt(grey, 0, 1), (std::array<uint8_t, 3>{77, 77, 77}));
  EXPECT_FALSE(rgbAt(grey, 2, 0));  // outside
  EXPECT_FALSE(rgbAt(cv::Mat(), 0, 0));
  EXPECT_FALSE(rgbAt(cv::Mat(2, 2, CV_16UC3), 0, 0));  // not a kind keyframes keep
}
