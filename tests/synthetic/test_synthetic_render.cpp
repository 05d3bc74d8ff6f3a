// Rendering tests: the depth is the exact z of the scene geometry in the pinhole model, frames
// agree with each other through the ground truth, renders are deterministic and richly textured.

#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/Statistics.h>
#include <slamdunk/synthetic/SyntheticRenderer.h>
#include <slamdunk/synthetic/SyntheticScene.h>
#include <slamdunk/synthetic/SyntheticSequence.h>

#include <mrpt/img/CImage.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfTexturedTriangles.h>

#include "KeypointSpread.h"

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>

using namespace slamdunk;

namespace {

/// A scene with one large textured plane through `p0` with normal `n` (world frame).
std::shared_ptr<mrpt::opengl::COpenGLScene> planeScene(const Eigen::Vector3d& p0,
                                                       const Eigen::Vector3d& n) {
  auto scene = mrpt::opengl::COpenGLScene::Create();
  auto obj = mrpt::opengl::CSetOfTexturedTriangles::Create();
  obj->enableLight(false);
  obj->enableTextureLinearInterpolation(true);
  obj->assignImage(
      mrpt::img::CImage(SyntheticScene::makeTexture(512, 512, 7), mrpt::img::DEEP_COPY));
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a).normalized();
  const double half = 8;  // larger than the view
  auto pt = [&](double sa, double sb) {
    const Eigen::Vector3d q = p0 + half * (sa * a + sb * b);
    return mrpt::math::TPoint3Df(float(q.x()), float(q.y()), float(q.z()));
  };
  mrpt::opengl::TTriangle t1(pt(-1, -1), pt(1, -1), pt(1, 1)), t2(pt(-1, -1), pt(1, 1), pt(-1, 1));
  t1.setColor(mrpt::img::TColor(255, 255, 255));
  t2.setColor(mrpt::img::TColor(255, 255, 255));
  obj->insertTriangle(t1);
  obj->insertTriangle(t2);
  scene->insert(obj);
  return scene;
}

struct Consistency {
  size_t compared = 0;
  double medianAbs = 0;  ///< metres
  double fractionWithin1cm = 0;
  double medianGreyDiff = 0;  ///< grey levels, colour registration check
};

/// Moves frame A's valid depth pixels into frame B with the ground truth and compares their z
/// with B's depth there (bilinear, only where B's four neighbours are valid).
Consistency compareFrames(SyntheticSequence& seq, size_t a, size_t b) {
  cv::Mat bgrA, depthA, bgrB, depthB, greyA, greyB;
  seq.renderImages(a, bgrA, depthA);
  seq.renderImages(b, bgrB, depthB);
  cv::cvtColor(bgrA, greyA, cv::COLOR_BGR2GRAY);
  cv::cvtColor(bgrB, greyB, cv::COLOR_BGR2GRAY);
  const CameraIntrinsics K = seq.options().intrinsics();
  const Pose T_b_a = seq.groundTruth()[b].pose.inverse() * seq.groundTruth()[a].pose;
  std::vector<double> residuals, greyDiffs;
  size_t within = 0;
  for (int v = 0; v < depthA.rows; v += 3) {
    for (int u = 0; u < depthA.cols; u += 3) {
      const float z = depthA.at<float>(v, u);
      if (z <= 0) continue;
      const Eigen::Vector3d pb = T_b_a * K.backProject(u, v, z);
      if (pb.z() <= 0.1) continue;
      const Eigen::Vector2d px = K.project(pb);
      const int u0 = int(std::floor(px.x())), v0 = int(std::floor(px.y()));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= depthB.cols || v0 + 1 >= depthB.rows) continue;
      const float d00 = depthB.at<float>(v0, u0), d10 = depthB.at<float>(v0, u0 + 1);
      const float d01 = depthB.at<float>(v0 + 1, u0), d11 = depthB.at<float>(v0 + 1, u0 + 1);
      if (d00 <= 0 || d10 <= 0 || d01 <= 0 || d11 <= 0) continue;
      const double fu = px.x() - u0, fv = px.y() - v0;
      const double dB = (1 - fv) * ((1 - fu) * d00 + fu * d10) + fv * ((1 - fu) * d01 + fu * d11);
      const double r = std::abs(dB - pb.z());
      residuals.push_back(r);
      if (r < 0.01) {
        ++within;
        greyDiffs.push_back(
            std::abs(double(greyA.at<uint8_t>(v, u)) -
                     greyB.at<uint8_t>(int(std::lround(px.y())), int(std::lround(px.x())))));
      }
    }
  }
  Consistency c;
  c.compared = residuals.size();
  if (residuals.empty()) return c;
  c.medianAbs = upperMedian(residuals);
  c.fractionWithin1cm = double(within) / residuals.size();
  c.medianGreyDiff = greyDiffs.empty() ? 255 : upperMedian(greyDiffs);
  return c;
}

SyntheticOptions optionsFor(const std::string& trajectory) {
  SyntheticOptions o;
  o.trajectory = trajectory;
  return o;
}

}  // namespace

TEST(SyntheticRenderer, DepthIsZDepthOfAFrontoParallelWall) {
  // Camera translated and yawed; wall perpendicular to its optical axis 2.5 m ahead. At the
  // image corners the ray is 1.2x longer than z: a ray-distance depth would fail by 50 cm.
  Pose T_w_opt = Pose::Identity();
  T_w_opt.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_w_opt.translation() = Eigen::Vector3d(0.3, -0.2, 0.1);
  const double distance = 2.5;
  const Eigen::Vector3d axis = T_w_opt.linear().col(2);
  for (int ss : {1, 3}) {
    // A scene keeps the OpenGL objects of the context that first drew it: one per renderer.
    auto scene = planeScene(T_w_opt.translation() + distance * axis, axis);
    SyntheticRenderer renderer(CameraIntrinsics{}, ss);
    cv::Mat bgr, depth;
    renderer.render(*scene, T_w_opt, bgr, depth);
    ASSERT_EQ(depth.type(), CV_32F);
    ASSERT_EQ(depth.size(), cv::Size(640, 480));
    double maxErr = 0;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u)
        maxErr = std::max(maxErr, std::abs(depth.at<float>(v, u) - distance));
    std::printf("[ z-depth ] supersampling %d: max |depth - %.1f m| = %.3f mm\n", ss, distance,
                maxErr * 1000);
    EXPECT_LT(maxErr, 0.001) << "supersampling " << ss;
    for (auto [v, u] : {std::pair{0, 0}, {0, 639}, {479, 0}, {479, 639}})
      EXPECT_NEAR(depth.at<float>(v, u), distance, 0.001) << "corner " << u << "," << v;
  }
}

TEST(SyntheticRenderer, SlantedPlaneMatchesThePinholeModelAtPixelCentres) {
  // A plane slanted about both image axes: depth changes by ~1 cm per pixel, so a half-pixel
  // offset between OpenGL's and the pinhole model's pixel centres (in u or v) shows up as
  // millimetres of error.
  const Eigen::Vector3d n = Eigen::Vector3d(0.5, -0.4, -1.0).normalized();
  const Eigen::Vector3d p0(0, 0, 2.0);
  const CameraIntrinsics K;
  for (int ss : {1, 3}) {
    auto scene = planeScene(p0, n);
    SyntheticRenderer renderer(K, ss);
    cv::Mat bgr, depth;
    renderer.render(*scene, Pose::Identity(), bgr, depth);
    double maxErr = 0;
    size_t valid = 0;
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u) {
        const Eigen::Vector3d ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
        const double z = n.dot(p0) / n.dot(ray);  // ray * z lies on the plane
        if (z < SyntheticRenderer::kNearClip || z > SyntheticRenderer::kFarClip) continue;
        ++valid;
        maxErr = std::max(maxErr, std::abs(depth.at<float>(v, u) - z));
      }
    }
    std::printf("[ slanted ] supersampling %d: max |depth - pinhole z| = %.3f mm over %zu px\n", ss,
                maxErr * 1000, valid);
    EXPECT_GT(valid, 300000u);
    EXPECT_LT(maxErr, 0.001) << "supersampling " << ss;
  }
}

TEST(SyntheticSequence, FramesAgreeThroughTheGroundTruth) {
  const std::vector<std::pair<std::string, std::vector<std::pair<size_t, size_t>>>> cases = {
      {"sweep", {{0, 4}, {60, 66}, {140, 149}}},
      // Includes a pair across the loop's end: frame 399 is frame 0 again.
      {"loop", {{0, 5}, {133, 139}, {270, 278}, {395, 3}}},
  };
  for (const auto& [name, pairs] : cases) {
    SyntheticSequence seq(optionsFor(name));
    for (const auto& [a, b] : pairs) {
      SCOPED_TRACE(name + " frames " + std::to_string(a) + " -> " + std::to_string(b));
      const Consistency c = compareFrames(seq, a, b);
      std::printf(
          "[ consistency ] %s %zu->%zu: %zu points, median |dz| %.3f mm, %.1f%% within "
          "1 cm, median grey diff %.1f\n",
          name.c_str(), a, b, c.compared, c.medianAbs * 1000, 100 * c.fractionWithin1cm,
          c.medianGreyDiff);
      EXPECT_GT(c.compared, 10000u);
      EXPECT_LT(c.medianAbs, 0.001);
      EXPECT_GT(c.fractionWithin1cm, 0.9);
      EXPECT_LE(c.medianGreyDiff, 8);
    }
  }
}

TEST(SyntheticSequence, ObservationLayoutMatchesTheTumConverter) {
  SyntheticOptions o = optionsFor("sweep");
  o.frames = 20;
  SyntheticSequence seq(o);
  const auto obs = seq.renderFrame(7);
  EXPECT_EQ(obs->sensorLabel, "SYNTH_RGBD");
  EXPECT_NEAR(mrpt::Clock::toDouble(obs->timestamp), seq.groundTruth()[7].timestamp, 1e-6);
  EXPECT_TRUE(obs->hasRangeImage);
  EXPECT_TRUE(obs->range_is_depth);
  EXPECT_FLOAT_EQ(obs->rangeUnits, 1.0f / 5000);
  EXPECT_EQ(obs->rangeImage.rows(), 480);
  EXPECT_EQ(obs->rangeImage.cols(), 640);
  EXPECT_TRUE(obs->hasIntensityImage);
  EXPECT_TRUE(obs->intensityImage.isColor());
  EXPECT_TRUE(obs->doDepthAndIntensityCamerasCoincide());
  EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.fx(), 525);
  EXPECT_DOUBLE_EQ(obs->cameraParamsIntensity.cx(), 319.5);
  EXPECT_DOUBLE_EQ(obs->cameraParams.cy(), 239.5);
  EXPECT_EQ(obs->cameraParams.ncols, 640u);

  // The pipeline's view of it equals the rendered images.
  const RgbdFrame frame = RgbdFrame::fromObservation(*obs);
  cv::Mat bgr, depth;
  seq.renderImages(7, bgr, depth);
  EXPECT_EQ(cv::norm(frame.depth(), depth, cv::NORM_INF), 0.0);
  EXPECT_GT(frame.validDepthFraction(), 0.99);  // a closed room: every pixel sees a surface
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(frame.grey(), grey, cv::NORM_INF), 0.0);
}

TEST(SyntheticSequence, DeterministicAcrossInstances) {
  // Two independent instances (own scene, textures and OpenGL context), frames in a different
  // order: identical depth and colour.
  SyntheticOptions o = optionsFor("loop");
  o.depthNoiseSigma = 0.002;  // the noise must be deterministic too
  const std::vector<size_t> frames = {17, 250};
  std::vector<cv::Mat> bgr1, depth1;
  {
    SyntheticSequence seq(o);
    for (size_t i : frames) {
      cv::Mat b, d;
      seq.renderImages(i, b, d);
      bgr1.push_back(b);
      depth1.push_back(d);
    }
  }
  SyntheticSequence seq(o);
  for (size_t k = frames.size(); k-- > 0;) {
    cv::Mat b, d;
    seq.renderImages(frames[k], b, d);
    EXPECT_EQ(cv::norm(d, depth1[k], cv::NORM_INF), 0.0) << "frame " << frames[k];
    EXPECT_EQ(cv::norm(b, bgr1[k], cv::NORM_INF), 0.0) << "frame " << frames[k];
  }
  // A different seed changes the textures.
  o.seed = 2;
  SyntheticSequence other(o);
  cv::Mat b, d;
  other.renderImages(frames[0], b, d);
  EXPECT_GT(cv::norm(b, bgr1[0], cv::NORM_L1) / b.total(), 10.0);
}

TEST(SyntheticSequence, DepthNoiseHasTheRequestedSigma) {
  SyntheticOptions exact = optionsFor("sweep"), noisy = optionsFor("sweep");
  noisy.depthNoiseSigma = 0.01;
  cv::Mat b, d0, d1;
  SyntheticSequence(exact).renderImages(30, b, d0);
  SyntheticSequence(noisy).renderImages(30, b, d1);
  cv::Scalar mean, stddev;
  cv::meanStdDev(d1 - d0, mean, stddev, d0 > 0);
  EXPECT_NEAR(stddev[0], 0.01, 0.0005);
  EXPECT_NEAR(mean[0], 0.0, 0.0005);
}

TEST(KinectDepth, NoiseGrowsWithSquaredDepthOnTheDisparityLattice) {
  const double fx = 525, fb = fx * 0.075;
  // σ_z = z² σ_d / (f b) with σ_d² = 0.07² + (1/8)² / 12 (noise plus quantisation), in px.
  const double sigmaD = std::sqrt(0.07 * 0.07 + 0.125 * 0.125 / 12);
  for (const double z : {1.0, 2.0, 3.0}) {
    cv::Mat plane(120, 160, CV_32F, cv::Scalar(z));
    plane(cv::Rect(0, 0, 20, 120)).setTo(0);  // a hole stays a hole
    const cv::Mat k = kinectDepth(plane, fx, 7);
    const cv::Mat valid = plane > 0;
    EXPECT_EQ(cv::countNonZero(k(cv::Rect(0, 0, 19, 120))), 0) << z;
    cv::Scalar mean, stddev;
    cv::meanStdDev(k, mean, stddev, valid & (k > 0));
    const double expected = z * z * sigmaD / fb;
    EXPECT_NEAR(stddev[0], expected, 0.2 * expected) << "z = " << z;
    EXPECT_NEAR(mean[0], z, 0.003 * z) << "z = " << z;
    // Every value is f b over a whole number of 1/8 px.
    int offLattice = 0;
    for (int v = 0; v < k.rows; ++v)
      for (int u = 20; u < k.cols; ++u) {
        const float d = k.at<float>(v, u);
        if (d <= 0) continue;
        const double eighths = 8 * fb / d;
        offLattice += std::abs(eighths - std::round(eighths)) > 1e-2;
      }
    EXPECT_EQ(offLattice, 0) << "z = " << z;
  }
  const cv::Mat plane(60, 80, CV_32F, cv::Scalar(2.0));
  EXPECT_EQ(cv::norm(kinectDepth(plane, fx, 3), kinectDepth(plane, fx, 3), cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(kinectDepth(plane, fx, 3), kinectDepth(plane, fx, 4), cv::NORM_INF), 0);
}

TEST(SyntheticSequence, TexturesGiveManyWellSpreadKeypoints) {
  for (const auto& [name, frames] : std::vector<std::pair<std::string, std::vector<size_t>>>{
           {"sweep", {0, 75, 149}}, {"loop", {0, 100, 200, 300}}}) {
    SyntheticSequence seq(optionsFor(name));
    for (size_t i : frames) {
      cv::Mat bgr, depth;
      seq.renderImages(i, bgr, depth);
      const test::KeypointSpread spread = test::keypointSpread(bgr);
      std::printf("[ keypoints ] %s frame %zu: %zu ORB keypoints, %d/16 cells\n", name.c_str(), i,
                  spread.keypoints, spread.occupiedCells);
      EXPECT_GT(spread.keypoints, 300u) << name << " frame " << i;
      EXPECT_GE(spread.occupiedCells, 12) << name << " frame " << i;
    }
  }
}

TEST(SyntheticSequence, FeatureMatchesAreUnambiguous) {
  // Non-repetitive textures: nearest-neighbour ORB matches between frames a few frames apart
  // (ratio test) land where the ground truth says, almost without exception.
  auto orb = cv::ORB::create(1500);
  for (const auto& [name, a, b] : std::vector<std::tuple<std::string, size_t, size_t>>{
           {"sweep", 20, 30}, {"loop", 200, 208}}) {
    SyntheticSequence seq(optionsFor(name));
    cv::Mat bgrA, depthA, bgrB, depthB;
    seq.renderImages(a, bgrA, depthA);
    seq.renderImages(b, bgrB, depthB);
    std::vector<cv::KeyPoint> kpA, kpB;
    cv::Mat descA, descB;
    orb->detectAndCompute(bgrA, cv::noArray(), kpA, descA);
    orb->detectAndCompute(bgrB, cv::noArray(), kpB, descB);
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(descA, descB, knn, 2);
    const CameraIntrinsics K = seq.options().intrinsics();
    const Pose T_b_a = seq.groundTruth()[b].pose.inverse() * seq.groundTruth()[a].pose;
    size_t matches = 0, correct = 0;
    for (const auto& m : knn) {
      if (m.size() < 2 || m[0].distance > 0.8 * m[1].distance) continue;
      const cv::Point2f pa = kpA[m[0].queryIdx].pt, pb = kpB[m[0].trainIdx].pt;
      const float z = depthA.at<float>(int(std::lround(pa.y)), int(std::lround(pa.x)));
      if (z <= 0) continue;
      ++matches;
      const Eigen::Vector2d expected = K.project(T_b_a * K.backProject(pa.x, pa.y, z));
      if ((expected - Eigen::Vector2d(pb.x, pb.y)).norm() < 3.0) ++correct;
    }
    std::printf(
        "[ matches ] %s %zu->%zu: %zu ratio-test matches, %.1f%% where the ground truth "
        "puts them\n",
        name.c_str(), a, b, matches, 100.0 * correct / std::max<size_t>(1, matches));
    EXPECT_GT(matches, 300u) << name;
    EXPECT_GT(double(correct) / matches, 0.9) << name;
  }
}

TEST(SyntheticSequence, RejectsBadOptions) {
  SyntheticOptions o;
  o.trajectory = "nope";
  EXPECT_THROW(SyntheticSequence{o}, std::invalid_argument);
  o = SyntheticOptions{};
  o.frames = 1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = SyntheticOptions{};
  o.depthNoiseSigma = -0.1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o = SyntheticOptions{};
  o.supersampling = 2;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  EXPECT_NO_THROW(SyntheticOptions{}.validate());
}
