// DepthOnlyFallback against a keyframe of ray-cast planes: it registers a frame that moved by
// a known pose, refuses a single wall (the camera could slide along it), and is not tried when
// the tracker is lost or the reference is gone.

#include <slamdunk/tracking/DepthOnlyFallback.h>

#include "RenderPlanes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace slamdunk;

namespace {

Pose poseOf(double degrees, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d(0.3, 1, 0.2).normalized())
                   .toRotationMatrix();
  p.translation() = t;
  return p;
}

/// A map of one keyframe (id 0, at the origin) seeing `planes`, and a fallback aligning with it.
struct Scene {
  TrackerOptions options;
  KeyframeGraph graph;
  DenseDepthTerm dense{options, graph};
  DepthOnlyFallback fallback{options, graph, dense};
  std::vector<test::Plane> planes;

  explicit Scene(std::vector<test::Plane> p) : planes(std::move(p)) {
    options.depthAlignmentStride = 4;
    auto kf = std::make_shared<Keyframe>();
    kf->id = 0;
    kf->intrinsics = test::smallCamera();
    kf->depthSmallStride = 1;
    kf->depthSmall = test::renderPlanes(kf->intrinsics, Pose::Identity(), planes);
    graph.addKeyframe(kf, Pose::Identity());
  }
  RgbdFrame frameAt(const Pose& pose) const {
    const CameraIntrinsics K = test::smallCamera();
    return RgbdFrame(1.0, cv::Mat(K.height, K.width, CV_8U, cv::Scalar(0)),
                     test::renderPlanes(K, pose, planes), K);
  }
};

}  // namespace

TEST(DepthOnlyFallback, RegistersAMovedViewOfACorner) {
  Scene s(test::cornerPlanes());
  const Pose truth = poseOf(1.5, {0.03, -0.01, 0.02});
  const auto r = s.fallback.registerFrame(s.frameAt(truth), 0, Pose::Identity(), Pose::Identity(),
                                          std::nullopt);
  ASSERT_TRUE(r.registered) << r.failure;
  EXPECT_LT(translationDistance(r.pose, truth), 0.002);
  EXPECT_LT(
      Eigen::AngleAxisd(Eigen::Matrix3d(r.pose.linear().transpose() * truth.linear())).angle(),
      0.1 * M_PI / 180);
  EXPECT_GT(r.overlap, 0.8);
  // The term kept for the keyframe's depth edge has the dense term's gate, not the coarse ones.
  EXPECT_EQ(r.term.maxDistance, s.options.depthAlignmentMaxDistance);
}

TEST(DepthOnlyFallback, ThePredictedMotionHelpsAFastCamera) {
  Scene s(test::cornerPlanes());
  const Pose step = poseOf(1.0, {0.04, 0, 0.03});
  const Pose last = step, truth = step * step;
  const auto r = s.fallback.registerFrame(s.frameAt(truth), 0, Pose::Identity(), last, step);
  ASSERT_TRUE(r.registered) << r.failure;
  EXPECT_LT(translationDistance(r.pose, truth), 0.002);
}

TEST(DepthOnlyFallback, RefusesASingleWall) {
  Scene s({{{0, 0, -1}, 2.5}});
  const auto r = s.fallback.registerFrame(s.frameAt(poseOf(0.5, {0.02, 0, 0})), 0, Pose::Identity(),
                                          Pose::Identity(), std::nullopt);
  EXPECT_FALSE(r.registered);
  EXPECT_FALSE(r.failure.empty());
}

TEST(DepthOnlyFallback, RefusesAKeyframeWithoutDepth) {
  Scene s(test::cornerPlanes());
  auto bare = std::make_shared<Keyframe>();
  bare->id = 1;
  s.graph.addKeyframe(bare, Pose::Identity());
  const auto r = s.fallback.registerFrame(s.frameAt(Pose::Identity()), 1, Pose::Identity(),
                                          Pose::Identity(), std::nullopt);
  EXPECT_FALSE(r.registered);
  EXPECT_NE(r.failure.find("no depth"), std::string::npos) << r.failure;
}

TEST(DepthOnlyFallback, OnlyRightAfterATrackedFrame) {
  Scene s(test::cornerPlanes());
  EXPECT_TRUE(s.fallback.possible(false, 0));
  EXPECT_FALSE(s.fallback.possible(true, 0));   // lost: relocalization's job
  EXPECT_FALSE(s.fallback.possible(false, 7));  // no such reference keyframe
  s.options.depthOnlyFallback = false;
  EXPECT_FALSE(s.fallback.possible(false, 0));
}
