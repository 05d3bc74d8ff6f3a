// ViewCoverage: the share of a frame's points a keyframe sees from nearly the same place.

#include <slamdunk/tracking/ViewCoverage.h>

#include <gtest/gtest.h>

using namespace slamdunk;

namespace {

/// A wall of points 2 m in front of the camera, spread over the middle of its view
/// (within +-20 degrees), in that camera's optical frame.
std::vector<Eigen::Vector3d> wallInView() {
  std::vector<Eigen::Vector3d> points;
  for (double x = -0.6; x <= 0.6; x += 0.1)
    for (double y = -0.4; y <= 0.4; y += 0.1) points.emplace_back(x, y, 2.0);
  return points;
}

Pose turnedAboutY(double degrees, const Eigen::Vector3d& position = Eigen::Vector3d::Zero()) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(degrees * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = position;
  return T;
}

/// A graph with one keyframe at the origin; with `nearerSurfaceAt` > 0 its depth shows a
/// surface at that distance everywhere.
std::unique_ptr<KeyframeGraph> oneKeyframe(double nearerSurfaceAt = 0) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = 0;
  if (nearerSurfaceAt > 0) {
    kf->depthSmallStride = 4;
    kf->depthSmall = cv::Mat(120, 160, CV_32F, cv::Scalar(nearerSurfaceAt));
  }
  auto graph = std::make_unique<KeyframeGraph>();
  graph->addKeyframe(kf, Pose::Identity());
  return graph;
}

}  // namespace

TEST(ViewCoverage, TheKeyframesOwnViewIsCovered) {
  const auto graph = oneKeyframe();
  EXPECT_DOUBLE_EQ(ViewCoverage().coveredShare(wallInView(), Pose::Identity(), *graph, {0}), 1.0);
  // Turned a little in place: the same wall, seen from the same place.
  EXPECT_DOUBLE_EQ(ViewCoverage().coveredShare(wallInView(), turnedAboutY(5), *graph, {0}), 1.0);
}

TEST(ViewCoverage, WhatTheKeyframeDoesNotShowIsNot) {
  const auto graph = oneKeyframe();
  const ViewCoverage coverage;
  // Turned 60 degrees: the wall the frame sees is outside the keyframe's image.
  EXPECT_DOUBLE_EQ(coverage.coveredShare(wallInView(), turnedAboutY(60), *graph, {0}), 0.0);
  // No keyframe to see anything, or nothing to see.
  EXPECT_DOUBLE_EQ(coverage.coveredShare(wallInView(), Pose::Identity(), *graph, {}), 0.0);
  EXPECT_DOUBLE_EQ(coverage.coveredShare({}, Pose::Identity(), *graph, {0}), 0.0);
}

TEST(ViewCoverage, ASurfaceSeenFromElsewhereIsNotCovered) {
  const auto graph = oneKeyframe();
  const ViewCoverage coverage;  // within 15 degrees and a distance ratio of 1.25
  // 1.2 m to the side, turned to look at the same wall: about 30 degrees off the keyframe's
  // rays, where its features would no longer match.
  const Pose side = turnedAboutY(-30, {1.2, 0, 0});
  EXPECT_LT(coverage.coveredShare(wallInView(), side, *graph, {0}), 0.1);
  // 1 m closer: the wall at half the keyframe's distance, at twice its scale.
  const Pose closer = turnedAboutY(0, {0, 0, 1.0});
  const std::vector<Eigen::Vector3d> nearWall = [] {
    auto points = wallInView();
    for (auto& p : points) p.z() = 1.0;
    return points;
  }();
  EXPECT_DOUBLE_EQ(coverage.coveredShare(nearWall, closer, *graph, {0}), 0.0);
}

TEST(ViewCoverage, ASurfaceHiddenInTheKeyframeIsNotCovered) {
  // The keyframe's depth shows something 1 m away where the frame sees the wall at 2 m.
  EXPECT_DOUBLE_EQ(
      ViewCoverage().coveredShare(wallInView(), Pose::Identity(), *oneKeyframe(1.0), {0}), 0.0);
  // Its depth shows the wall itself (within the noise): covered.
  EXPECT_DOUBLE_EQ(
      ViewCoverage().coveredShare(wallInView(), Pose::Identity(), *oneKeyframe(1.98), {0}), 1.0);
}
