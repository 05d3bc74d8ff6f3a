// FrameRegistrar on exact data: a frame seeing a keyframe's points from a known pose is
// registered at that pose, and a registration that jumps too far from the last tracked pose is
// refused.

#include <slamdunk/tracking/FrameRegistrar.h>
#include <slamdunk/tracking/KeyframeEdges.h>

#include "PoolTestData.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

using namespace slamdunk;

namespace {

/// A keyframe (id 0, at the world origin) with n features at random points 1.5-3 m ahead.
KeyframePtr keyframeWithScatteredPoints(int n) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = 0;
  kf->features.descriptors = test::randomDescriptors(n, 11);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0), depth(1.5, 3.0);
  for (int i = 0; i < n; ++i) {
    kf->features.keypoints.emplace_back(cv::Point2f(10.f + i % 300, 10.f + i / 300), 10.f);
    kf->features.points.emplace_back(lateral(rng), 0.6 * lateral(rng), depth(rng));
  }
  return kf;
}

/// The same features seen from a camera at `pose` (world <- camera).
FeatureSet seenFrom(const Keyframe& kf, const Pose& pose) {
  FeatureSet f = kf.features;
  for (auto& p : f.points) p = pose.inverse() * p;
  return f;
}

Pose moved(double metres, double degrees) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d(0.2, 1, 0.1).normalized())
                   .toRotationMatrix();
  p.translation() = Eigen::Vector3d(metres, 0.3 * metres, -0.5 * metres);
  return p;
}

struct Fixture {
  TrackerOptions options;
  DepthNoiseModel noise;
  SensorTiming timing{SensorTimingOptions{}};
  KeyframeGraph graph;
  DenseDepthTerm dense{options, graph};
  FeaturePool pool;
  RgbdFrame frame{1.0, cv::Mat(480, 640, CV_8U, cv::Scalar(0)),
                  cv::Mat(480, 640, CV_32F, cv::Scalar(0)), CameraIntrinsics{}};

  Fixture() {
    options.localMap.pool.frustumFilter = false;
    graph.addKeyframe(keyframeWithScatteredPoints(300), Pose::Identity());
    pool = FeaturePool(options.localMap.pool);
    pool.build(graph, {0}, Pose::Identity(), CameraIntrinsics{});
  }

  /// The keyframe's features seen from `truth`, registered from the origin.
  Registration registerSeenFrom(const Pose& truth) {
    FrameRegistrar registrar(options, noise, timing, graph, dense);
    registrar.newFrame(Pose::Identity());
    return registrar.registerFrame(pool, frame, seenFrom(*graph.keyframe(0), truth));
  }
};

}  // namespace

TEST(FrameRegistrar, RegistersAFrameAtTheMotionItWasSeenFrom) {
  Fixture s;
  const Pose truth = moved(0.05, 3);
  const Registration r = s.registerSeenFrom(truth);
  ASSERT_TRUE(r) << r.failure;
  EXPECT_EQ(r.pool, &s.pool);
  EXPECT_EQ(r.inliers, 300u);
  EXPECT_EQ(r.inlierMatches.size(), 300u);
  EXPECT_EQ(r.inlierSamples.size(), 300u);
  EXPECT_LT(translationDistance(r.pose, truth), 1e-6);
  EXPECT_LT(
      Eigen::AngleAxisd(Eigen::Matrix3d(r.pose.linear().transpose() * truth.linear())).angle(),
      1e-6);
  EXPECT_TRUE(r.rejectedPixels.empty());
}

TEST(FrameRegistrar, RefusesAJumpFromTheLastTrackedPose) {
  Fixture s;
  s.options.maxTranslationJump = 0.5;
  FrameRegistrar registrar(s.options, s.noise, s.timing, s.graph, s.dense);
  const Pose truth = moved(0.4, 2);  // 0.46 m from the origin
  const FeatureSet features = seenFrom(*s.graph.keyframe(0), truth);

  registrar.newFrame(moved(-0.4, 0));  // 0.92 m away
  const Registration far = registrar.registerFrame(s.pool, s.frame, features);
  EXPECT_FALSE(far);
  EXPECT_NE(far.failure.find("implausible jump"), std::string::npos) << far.failure;

  registrar.newFrame(std::nullopt);  // lost: nothing to jump from
  EXPECT_TRUE(registrar.registerFrame(s.pool, s.frame, features));
}

TEST(FrameRegistrar, ReadsEachKeyframePoseOncePerFrame) {
  Fixture s;
  FrameRegistrar registrar(s.options, s.noise, s.timing, s.graph, s.dense);
  registrar.newFrame(std::nullopt);
  const Pose before = registrar.keyframePose(0);
  s.graph.setPoses({{0, moved(0.1, 5)}}, {});  // the optimizer moves it meanwhile
  EXPECT_LT(translationDistance(registrar.keyframePose(0), before), 1e-12);
  registrar.newFrame(std::nullopt);
  EXPECT_NEAR(translationDistance(registrar.keyframePose(0), before),
              translationDistance(moved(0.1, 5), Pose::Identity()), 1e-12);
}

// A new keyframe is linked to the keyframe holding its inliers, with one weighted match per
// inlier, and to none when they are fewer than edge_min_matches.
TEST(KeyframeEdges, LinksTheKeyframeHoldingEnoughInliers) {
  for (const int minMatches : {5, 301}) {
    Fixture s;
    s.options.edgeMinMatches = minMatches;
    const Registration r = s.registerSeenFrom(moved(0.05, 3));
    ASSERT_TRUE(r) << r.failure;
    auto kf = std::make_shared<Keyframe>();
    kf->id = 1;
    kf->features = r.features;
    s.graph.addKeyframe(kf, r.pose);

    KeyframeEdges(s.options, s.noise, s.graph, s.dense).linkMatches(1, kf->features, r);
    const std::vector<KeyframeEdge> edges = s.graph.allEdges();
    if (minMatches > 300) {
      EXPECT_TRUE(edges.empty());
      continue;
    }
    ASSERT_EQ(edges.size(), 1u);
    EXPECT_EQ(edges[0].matches.size(), 300u);
    for (const PointMatch& m : edges[0].matches) EXPECT_GT(m.weight, 0);
  }
}
