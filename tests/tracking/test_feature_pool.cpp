#include <slamdunk/mapping/FeaturePool.h>

#include "PoolTestData.h"

#include <gtest/gtest.h>

#include <random>

using namespace slamdunk;

using test::makeKeyframe;
using test::randomDescriptors;

TEST(FeaturePool, MultiViewRatioUsesSameKeyframeNeighbour) {
  // The same descriptors seen from two keyframes: a plain ratio test would find d0 ≈ d1 and
  // reject every match; the multi-view test compares against the same keyframe only.
  const cv::Mat d = randomDescriptors(200, 1);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d), Pose::Identity());
  graph.addKeyframe(makeKeyframe(1, d), Pose::Identity());
  FeaturePool pool;
  CameraIntrinsics K;
  pool.build(graph, {0, 1}, Pose::Identity(), K);
  ASSERT_EQ(pool.size(), 400u);
  cv::Mat query = d.clone();
  query += 0.01 * randomDescriptors(200, 2);
  const auto matches = pool.match(query, 0.8);
  EXPECT_GT(matches.size(), 190u);
  for (const auto& m : matches) {
    EXPECT_EQ(pool.feature(m.pool).index, m.query);
    EXPECT_LT(m.ratio, 0.8);
  }
}

TEST(FeaturePool, FrustumFilterDropsPointsBehindTheCentre) {
  const cv::Mat d = randomDescriptors(50, 3);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d), Pose::Identity());
  Pose turned = Pose::Identity();  // looking backwards: the points are behind it
  turned.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  FeaturePool pool;
  pool.build(graph, {0}, turned, CameraIntrinsics());
  EXPECT_EQ(pool.size(), 0u);
  pool.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
  EXPECT_EQ(pool.size(), 50u);
}

TEST(FeaturePool, BinaryDescriptorsAndDeterminism) {
  cv::Mat d(300, 32, CV_8U);
  cv::RNG rng(5);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d), Pose::Identity());
  for (const int bruteForceBelow : {0, 1000}) {  // LSH index, then brute force (Hamming)
    FeaturePoolOptions options;
    options.bruteForceBelow = bruteForceBelow;
    FeaturePool a(options), b(options);
    a.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
    b.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
    ASSERT_EQ(a.parts().front()->bruteForce(), bruteForceBelow > 0);
    const auto ma = a.match(d, 0.8), mb = b.match(d, 0.8);
    EXPECT_GT(ma.size(), 250u);
    ASSERT_EQ(ma.size(), mb.size());
    for (size_t i = 0; i < ma.size(); ++i) EXPECT_EQ(ma[i].pool, mb[i].pool);
  }
}

TEST(FeaturePool, SmallPartsAreSearchedExactly) {
  // A new keyframe's part (a few hundred features) is searched by brute force: every match is
  // the true nearest neighbour, with the true ratio to the second nearest.
  const cv::Mat d = randomDescriptors(600, 11);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d), Pose::Identity());
  cv::Mat query = d.rowRange(0, 300).clone();
  query += 0.25 * randomDescriptors(300, 12);
  FeaturePool pool;  // default: parts of at most 1000 features by brute force
  pool.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
  ASSERT_TRUE(pool.parts().front()->bruteForce());
  const auto matches = pool.match(query, 0.9);
  ASSERT_GT(matches.size(), 200u);
  for (const auto& m : matches) {
    std::vector<double> dist;
    for (int i = 0; i < d.rows; ++i) dist.push_back(cv::norm(query.row(m.query), d.row(i)));
    std::vector<double> sorted = dist;
    std::partial_sort(sorted.begin(), sorted.begin() + 2, sorted.end());
    EXPECT_NEAR(dist[pool.feature(m.pool).index], sorted[0], 1e-5);
    EXPECT_NEAR(m.ratio, sorted[0] / sorted[1], 1e-5);
  }
  // Above the threshold the part gets a KD-tree.
  FeaturePoolOptions indexed;
  indexed.bruteForceBelow = 500;
  FeaturePool big(indexed);
  big.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
  EXPECT_FALSE(big.parts().front()->bruteForce());
}

// nanoflann's KD-tree is exact: over a part too large for brute force it makes the matches, and
// the ratios, that brute force makes.
TEST(FeaturePool, NanoflannMatchesAsBruteForceDoes) {
  const cv::Mat d = randomDescriptors(1200, 21);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d.rowRange(0, 600).clone()), Pose::Identity());
  graph.addKeyframe(makeKeyframe(1, d.rowRange(600, 1200).clone()), Pose::Identity());
  cv::Mat query = d.rowRange(300, 900).clone();
  query += 0.3 * randomDescriptors(600, 22);
  auto matchesWith = [&](PoolIndexType index) {
    FeaturePoolOptions options;
    options.index = index;
    FeaturePool pool(options);
    pool.build(graph, {0, 1}, Pose::Identity(), CameraIntrinsics());
    EXPECT_EQ(pool.parts().front()->bruteForce(), index == PoolIndexType::Exact);
    return pool.match(query, 0.9);
  };
  const auto exact = matchesWith(PoolIndexType::Exact);
  const auto tree = matchesWith(PoolIndexType::Nanoflann);
  ASSERT_GT(exact.size(), 400u);
  ASSERT_EQ(tree.size(), exact.size());
  for (size_t i = 0; i < exact.size(); ++i) {
    EXPECT_EQ(tree[i].query, exact[i].query);
    EXPECT_EQ(tree[i].pool, exact[i].pool);
    EXPECT_NEAR(tree[i].ratio, exact[i].ratio, 1e-5);
  }
}

// Over its budget, a window's part keeps the features its keyframes saw from directions nearest
// the window centre's: there their descriptors match the camera's best.
TEST(FeaturePool, ABudgetKeepsTheFeaturesSeenFromNearestTheCentre) {
  const cv::Mat d = randomDescriptors(50, 5);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, d), Pose::Identity());
  // One metre to the side, turned to look at about the same place: its rays are 25-30 degrees
  // off the centre's.
  Pose side = Pose::Identity();
  side.linear() =
      Eigen::AngleAxisd(-26.6 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  side.translation() = Eigen::Vector3d(1.0, 0, 0);
  graph.addKeyframe(makeKeyframe(1, d), side);

  FeaturePool unlimited;
  unlimited.build(graph, {0, 1}, Pose::Identity(), CameraIntrinsics());
  EXPECT_EQ(unlimited.size(), 100u);

  FeaturePoolOptions options;
  options.budget = 50;
  FeaturePool budgeted(options);
  budgeted.build(graph, {1, 0}, Pose::Identity(), CameraIntrinsics());
  ASSERT_EQ(budgeted.size(), 50u);
  for (size_t i = 0; i < budgeted.size(); ++i) EXPECT_EQ(budgeted.feature(i).keyframe, 0u) << i;
}

// A keyframe may keep its float descriptors as half floats: the pool searches them as floats.
TEST(FeaturePool, HalfFloatKeyframeDescriptorsAreSearchedAsFloats) {
  const cv::Mat d = randomDescriptors(200, 6);
  cv::Mat half;
  d.convertTo(half, CV_16F);
  KeyframeGraph graph;
  graph.addKeyframe(makeKeyframe(0, half), Pose::Identity());
  FeaturePool pool;
  pool.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
  ASSERT_EQ(pool.size(), 200u);
  const auto matches = pool.match(d, 0.8);
  EXPECT_GT(matches.size(), 190u);
  for (const auto& m : matches) EXPECT_EQ(pool.feature(m.pool).index, m.query);
}
