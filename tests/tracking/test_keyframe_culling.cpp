// KeyframeCulling: a keyframe whose matched features other keyframes match too is culled, and
// the feature tracks that ran through it still join the keyframes that remain.

#include <slamdunk/graph/LandmarkTracks.h>
#include <slamdunk/mapping/KeyframeCulling.h>

#include <gtest/gtest.h>

#include <set>

using namespace slamdunk;

namespace {

constexpr int kFeatures = 10;

KeyframePtr keyframe(KeyframeId id) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  for (int i = 0; i < kFeatures; ++i) {
    kf->features.keypoints.emplace_back(float(10 * i), 50.f, 8.f);
    kf->features.points.emplace_back(0.1 * i, 0.0, 2.0);
  }
  return kf;
}

/// Features [first, last) of keyframe a matched to the same features of keyframe b.
std::vector<PointMatch> sameFeatures(int first, int last) {
  std::vector<PointMatch> out;
  for (int f = first; f < last; ++f) {
    PointMatch m{Eigen::Vector3d(0.1 * f, 0, 2), Eigen::Vector3d(0.1 * f, 0, 2)};
    m.featureI = m.featureJ = static_cast<uint32_t>(f);
    out.push_back(m);
  }
  return out;
}

/// Keyframes 0-3 in a row. Keyframe 1's features are all matched by keyframes 0 and 2, half
/// of them by keyframe 3 too; keyframe 3 shares only those with anyone.
void addOverlappingKeyframes(KeyframeGraph& graph) {
  for (KeyframeId id = 0; id < 4; ++id) {
    Pose T = Pose::Identity();
    T.translation().x() = 0.05 * id;
    graph.addKeyframe(keyframe(id), T);
  }
  graph.addMatches(0, 1, sameFeatures(0, kFeatures));
  graph.addMatches(1, 2, sameFeatures(0, kFeatures));
  graph.addMatches(1, 3, sameFeatures(0, kFeatures / 2));
}

/// The keyframes each landmark is seen by, as sets, over the whole graph.
std::multiset<std::set<KeyframeId>> landmarkViews(const KeyframeGraph& graph) {
  std::multiset<std::set<KeyframeId>> out;
  for (const Landmark& l : buildLandmarkTracks(graph.allEdges()).landmarks) {
    std::set<KeyframeId> seenBy;
    for (const LandmarkObservation& o : l.observations) seenBy.insert(o.keyframe);
    out.insert(seenBy);
  }
  return out;
}

}  // namespace

TEST(KeyframeCulling, MeasuresHowManyOfAKeyframesFeaturesOthersSee) {
  KeyframeGraph graph;
  addOverlappingKeyframes(graph);
  const KeyframeCulling byTwo({0.9, 2}), byThree({0.9, 3});
  const auto v = byTwo.examine(graph, 1);
  EXPECT_EQ(v.matchedFeatures, size_t(kFeatures));
  EXPECT_EQ(v.coveredFeatures, size_t(kFeatures));  // each by keyframes 0 and 2
  EXPECT_EQ(v.successor, 0u);                       // ties go to the smaller id
  EXPECT_EQ(byThree.examine(graph, 1).coveredFeatures, size_t(kFeatures / 2));
  // Keyframe 3's features are seen by three others through keyframe 1's tracks.
  EXPECT_DOUBLE_EQ(byThree.examine(graph, 3).coveredShare(), 1.0);
  EXPECT_DOUBLE_EQ(byThree.examine(graph, 0).coveredShare(), 0.5);
}

TEST(KeyframeCulling, CullsTheRedundantKeyframeAndKeepsItsTracksJoined) {
  KeyframeGraph graph;
  addOverlappingKeyframes(graph);
  const auto before = landmarkViews(graph);
  ASSERT_EQ(before.size(), size_t(kFeatures));

  EXPECT_TRUE(KeyframeCulling({0, 2}).cull(graph, {1, 2}).empty());  // 0: off
  const std::vector<KeyframeId> culled = KeyframeCulling({0.9, 2}).cull(graph, {1, 2});
  EXPECT_EQ(culled, std::vector<KeyframeId>{1});  // then 2's features are seen by one other
  EXPECT_FALSE(graph.contains(1));

  // The same landmarks, each seen by the same keyframes less the culled one.
  std::multiset<std::set<KeyframeId>> expected;
  for (std::set<KeyframeId> seenBy : before) {
    seenBy.erase(1);
    expected.insert(seenBy);
  }
  EXPECT_EQ(landmarkViews(graph), expected);
  // Keyframe 1 follows keyframe 0, its successor, 5 cm to its side.
  Pose moved = Pose::Identity();
  moved.translation() = Eigen::Vector3d(0, 1, 0);
  graph.setPoses({{0, moved}});
  EXPECT_TRUE(graph.pose(1).translation().isApprox(Eigen::Vector3d(0.05, 1, 0), 1e-12));
}
