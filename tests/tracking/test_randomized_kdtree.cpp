// RandomizedKdTree: exact when it may compare every row, close to exact with the checks the pool
// uses on descriptors near the indexed ones, the same answers for the same rows and seed, and
// whole on degenerate input (fewer rows than neighbours asked for, identical rows, no rows).

#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/mapping/RandomizedKdTree.h>

#include "PoolTestData.h"

#include <gtest/gtest.h>

#include <vector>

using namespace slamdunk;
using test::randomDescriptors;

namespace {
struct Neighbours {
  std::vector<int> indices;
  std::vector<float> distances;
};

Neighbours search(const RandomizedKdTree& tree, const cv::Mat& queries, int q, int k, int checks) {
  Neighbours n{std::vector<int>(k, -1), std::vector<float>(k, 0.f)};
  const int found =
      tree.knn(queries.ptr<float>(q), k, checks, n.indices.data(), n.distances.data());
  n.indices.resize(found);
  n.distances.resize(found);
  return n;
}

/// The k nearest rows by brute force, nearest first.
Neighbours exact(const cv::Mat& rows, const cv::Mat& queries, int q, int k) {
  cv::Mat d, idx;
  cv::batchDistance(queries.row(q), rows, d, CV_32F, idx, cv::NORM_L2, k);
  Neighbours n;
  for (int j = 0; j < k; ++j) {
    n.indices.push_back(idx.at<int>(0, j));
    n.distances.push_back(d.at<float>(0, j));
  }
  return n;
}

/// `rows` moved a little: each query's nearest row is the one it came from.
cv::Mat perturbed(const cv::Mat& rows, unsigned seed) {
  cv::Mat noise = randomDescriptors(rows.rows, seed);
  return rows + 0.2 * noise;
}
}  // namespace

TEST(RandomizedKdTree, ComparingEveryRowIsExact) {
  const cv::Mat rows = randomDescriptors(700, 1);
  const cv::Mat queries = randomDescriptors(40, 2);
  const RandomizedKdTree tree(rows, 7);
  ASSERT_EQ(tree.size(), 700u);
  for (int q = 0; q < queries.rows; ++q) {
    const Neighbours got = search(tree, queries, q, 4, 700);
    const Neighbours want = exact(rows, queries, q, 4);
    ASSERT_EQ(got.indices, want.indices) << "query " << q;
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(got.distances[j], want.distances[j], 1e-5);
  }
}

TEST(RandomizedKdTree, WithThePoolsChecksItFindsTheRowAQueryCameFrom) {
  const cv::Mat rows = randomDescriptors(10000, 3);
  const cv::Mat queries = perturbed(rows.rowRange(0, 500), 4);
  const RandomizedKdTree tree(rows, 7);
  int found = 0;
  for (int q = 0; q < queries.rows; ++q) {
    const Neighbours n = search(tree, queries, q, 4, 96);
    ASSERT_EQ(n.indices.size(), 4u);
    for (int j = 1; j < 4; ++j) EXPECT_LE(n.distances[j - 1], n.distances[j]);
    found += n.indices[0] == q;
  }
  EXPECT_GE(found, 475) << "of 500 queries, 96 rows compared each";
}

TEST(RandomizedKdTree, TheSameRowsAndSeedGiveTheSameAnswers) {
  const cv::Mat rows = randomDescriptors(3000, 5);
  const cv::Mat queries = randomDescriptors(100, 6);
  const RandomizedKdTree a(rows, 7), b(rows, 7), other(rows, 8);
  int differ = 0;
  for (int q = 0; q < queries.rows; ++q) {
    const Neighbours na = search(a, queries, q, 4, 32);
    EXPECT_EQ(na.indices, search(b, queries, q, 4, 32).indices);
    EXPECT_EQ(na.distances, search(b, queries, q, 4, 32).distances);
    differ += na.indices != search(other, queries, q, 4, 32).indices;
  }
  EXPECT_GT(differ, 0) << "another seed should draw another tree";
}

TEST(RandomizedKdTree, FewIdenticalOrNoRows) {
  const cv::Mat queries = randomDescriptors(1, 9);
  const RandomizedKdTree few(randomDescriptors(3, 10), 7);
  EXPECT_EQ(search(few, queries, 0, 4, 64).indices.size(), 3u);

  cv::Mat same(50, 64, CV_32F, cv::Scalar(0.125f));  // no dimension to split on
  const RandomizedKdTree identical(same, 7);
  const Neighbours n = search(identical, queries, 0, 4, 50);
  ASSERT_EQ(n.indices.size(), 4u);
  for (int j = 0; j < 4; ++j) {
    EXPECT_GE(n.indices[j], 0);
    EXPECT_LT(n.indices[j], 50);
  }

  const RandomizedKdTree none(cv::Mat(0, 64, CV_32F), 7);
  EXPECT_EQ(none.size(), 0u);
  EXPECT_TRUE(search(none, queries, 0, 4, 64).indices.empty());
  EXPECT_THROW(RandomizedKdTree(cv::Mat(5, 8, CV_8U), 7), std::invalid_argument);
}

// The pool's own use: a part too large for brute force, searched through the tree, matches
// descriptors near its own as the multi-view ratio test expects.
TEST(RandomizedKdTree, APoolPartSearchedThroughItMatchesItsOwnDescriptors) {
  const cv::Mat d = randomDescriptors(1500, 11);
  KeyframeGraph graph;
  graph.addKeyframe(test::makeKeyframe(0, d), Pose::Identity());
  FeaturePoolOptions options;
  options.index = PoolIndexType::KdTree;
  options.checks = 96;
  FeaturePool pool(options);
  pool.build(graph, {0}, Pose::Identity(), CameraIntrinsics());
  ASSERT_EQ(pool.size(), 1500u);
  ASSERT_FALSE(pool.parts().front()->bruteForce());
  const cv::Mat query = perturbed(d.rowRange(0, 300), 12);
  const auto matches = pool.match(query, 0.8);
  EXPECT_GT(matches.size(), 270u);
  size_t right = 0;
  for (const auto& m : matches) right += pool.feature(m.pool).index == m.query;
  EXPECT_GE(right, matches.size() - 3);
}
