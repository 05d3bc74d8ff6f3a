// The keyframe graph's own bookkeeping: edges stored from the smaller id's side, and the
// memory count the scale benchmark reports.
#include <slamdunk/graph/KeyframeGraph.h>

#include <gtest/gtest.h>

using namespace slamdunk;

namespace {

KeyframePtr keyframe(KeyframeId id, int features, bool withImages) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  for (int i = 0; i < features; ++i) {
    kf->features.keypoints.emplace_back(float(i), float(i), 8.f);
    kf->features.points.emplace_back(0.01 * i, 0.0, 1.0 + 0.01 * i);
  }
  kf->features.keypoints.shrink_to_fit();
  kf->features.points.shrink_to_fit();
  kf->features.descriptors = cv::Mat(features, 64, CV_32F, cv::Scalar(0.1f));
  kf->depthSmall = cv::Mat(120, 160, CV_16F, cv::Scalar(0));
  if (withImages) {
    kf->colour = cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
    kf->depth = cv::Mat(480, 640, CV_32F, cv::Scalar(0));
  }
  return kf;
}

std::vector<PointMatch> matches(int n) {
  std::vector<PointMatch> out;
  for (int i = 0; i < n; ++i)
    out.push_back({Eigen::Vector3d(0.1 * i, 0, 1), Eigen::Vector3d(0.1 * i, 0, 1), 1.0,
                   Eigen::Matrix3d::Identity()});
  return out;
}

}  // namespace

TEST(KeyframeGraph, MemoryCountsEveryKeyframeAndEdgeByteExactly) {
  KeyframeGraph graph;
  graph.addKeyframe(keyframe(0, 300, false), Pose::Identity());
  graph.addKeyframe(keyframe(1, 500, true), Pose::Identity());
  graph.addMatches(1, 0, matches(150));  // stored as (0, 1), in one allocation of 150

  const GraphMemory m = graph.memory();
  EXPECT_EQ(m.keyframes, 2u);
  const size_t perFeature = sizeof(cv::KeyPoint) + 64 * sizeof(float) + sizeof(Eigen::Vector3d);
  EXPECT_EQ(m.features, 2 * sizeof(Keyframe) + 800 * perFeature);
  EXPECT_EQ(m.depthSmall, 2u * 160 * 120 * 2);
  EXPECT_EQ(m.images, 640u * 480 * 3 + 640 * 480 * 4);
  EXPECT_EQ(m.edges, sizeof(KeyframeEdge) + 150 * sizeof(PointMatch));
  EXPECT_EQ(m.withoutImages(), m.features + m.depthSmall + m.edges);
  EXPECT_EQ(m.total(), m.withoutImages() + m.images);

  // A second batch on the same edge (a loop closure) grows it by exactly its size.
  graph.addMatches(0, 1, matches(40));
  EXPECT_EQ(graph.memory().edges, sizeof(KeyframeEdge) + 190 * sizeof(PointMatch));
}

TEST(KeyframeGraph, MatchesAreStoredFromTheSmallerIdsSide) {
  KeyframeGraph graph;
  graph.addKeyframe(keyframe(3, 1, false), Pose::Identity());
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(1, 0, 0);
  graph.addKeyframe(keyframe(7, 1, false), T);
  PointMatch m{Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6), 0.5,
               Eigen::Matrix3d::Identity()};
  graph.addMatches(7, 3, {m});
  const auto edges = graph.allEdges();
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].i, 3u);
  EXPECT_EQ(edges[0].j, 7u);
  ASSERT_EQ(edges[0].matches.size(), 1u);
  EXPECT_EQ(edges[0].matches[0].pointI, Eigen::Vector3d(4, 5, 6));  // keyframe 3's point
  EXPECT_EQ(edges[0].matches[0].pointJ, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(graph.neighbours(3), std::vector<KeyframeId>{7});
}

namespace {
Pose translatedBy(double x) {
  Pose p = Pose::Identity();
  p.translation() = Eigen::Vector3d(x, 0, 0);
  return p;
}
}  // namespace

// A culled keyframe leaves with its edges; the frames that referred to it follow its successor
// at the relative pose the two had when it was culled, through later optimizations.
TEST(KeyframeGraph, CulledKeyframeFollowsItsSuccessor) {
  KeyframeGraph graph;
  for (KeyframeId id : {0u, 1u, 2u}) graph.addKeyframe(keyframe(id, 4, false), translatedBy(id));
  graph.addMatches(0, 1, matches(3));
  graph.addMatches(1, 2, matches(2));
  KeyframeEdge rewired;
  rewired.i = 0;
  rewired.j = 2;
  rewired.matches = matches(1);

  graph.cullKeyframe(1, 2, {rewired});
  EXPECT_FALSE(graph.contains(1));
  EXPECT_EQ(graph.keyframe(1), nullptr);
  EXPECT_EQ(graph.keyframeCount(), 2u);
  EXPECT_EQ(graph.culledCount(), 1u);
  ASSERT_EQ(graph.edgeIds(), (std::vector<std::pair<KeyframeId, KeyframeId>>{{0, 2}}));
  EXPECT_EQ(graph.neighbours(0), std::vector<KeyframeId>{2});
  EXPECT_TRUE(graph.rings(1, 3).empty());
  EXPECT_EQ(graph.hopDistance(0, 2, 1), 1);

  // The successor moves: the culled keyframe's pose moves with it, 1 m behind.
  Pose moved = translatedBy(5);
  moved.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  graph.setPoses({{2, moved}, {1, translatedBy(42)}});  // keyframe 1 is gone: left out
  const Pose expected = moved * translatedBy(-1);
  EXPECT_TRUE(graph.pose(1).isApprox(expected, 1e-12));
  ASSERT_TRUE(graph.findPose(1));
  EXPECT_TRUE(graph.findPose(1)->isApprox(expected, 1e-12));
  EXPECT_FALSE(graph.findPose(7));
  EXPECT_THROW(graph.pose(7), std::out_of_range);
  EXPECT_EQ(graph.poses().count(1), 0u);

  // Culled in turn, the successor hands its followers on; snapshots keep the chain.
  graph.cullKeyframe(2, 0, {});
  const auto snapshot = graph.snapshot();
  EXPECT_TRUE(snapshot->pose(1).isApprox(expected, 1e-12));
  EXPECT_EQ(snapshot->culledCount(), 2u);
  EXPECT_THROW(graph.cullKeyframe(2, 0, {}), std::logic_error);
}

// A loaded map localized in: its anchored keyframes keep their poses and points whatever an
// optimization writes; the others move as told, a correction carries the newer ones.
TEST(KeyframeGraph, AnchoredKeyframesStayWhereTheyAre) {
  KeyframeGraph graph;
  for (KeyframeId id : {0u, 1u, 2u, 3u})
    graph.addKeyframe(keyframe(id, 4, false), Pose::Identity());
  graph.anchor({0, 1});
  EXPECT_TRUE(graph.isAnchored(1));
  EXPECT_FALSE(graph.isAnchored(2));
  EXPECT_EQ(graph.anchoredIds(), (std::set<KeyframeId>{0, 1}));

  Pose moved = Pose::Identity();
  moved.translation() = Eigen::Vector3d(1, 0, 0);
  graph.setPoses({{1, moved}, {2, moved}},
                 {{1, {{0, Eigen::Vector3d(9, 9, 9)}}}, {2, {{0, Eigen::Vector3d(9, 9, 9)}}}});
  EXPECT_TRUE(graph.pose(1).isApprox(Pose::Identity()));
  EXPECT_TRUE(graph.pose(2).isApprox(moved));
  EXPECT_EQ(graph.refinedPoints(1), nullptr);
  ASSERT_NE(graph.refinedPoints(2), nullptr);

  // A correction of keyframes up to 1 carries those added since (2, 3) with 1, which stays.
  graph.applyCorrection({{0, moved}, {1, moved}}, 1);
  EXPECT_TRUE(graph.pose(0).isApprox(Pose::Identity()));
  EXPECT_TRUE(graph.pose(1).isApprox(Pose::Identity()));
  EXPECT_TRUE(graph.pose(3).isApprox(Pose::Identity()));
  // Up to 2, not anchored: 2 moves, and 3 with it.
  Pose further = moved;
  further.translation().x() = 3;
  graph.applyCorrection({{2, further}}, 2);
  EXPECT_TRUE(graph.pose(2).isApprox(further));
  EXPECT_NEAR(graph.pose(3).translation().x(), 2, 1e-12);  // by 3 - 1 = 2 from where it was
}
