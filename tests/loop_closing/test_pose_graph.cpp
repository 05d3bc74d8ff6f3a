// The pose graph a loop correction starts with: a ring of keyframes whose odometry drifted is
// pulled back onto the truth by one loop constraint, and keyframes added meanwhile follow.
#include <slamdunk/loop_closing/LoopClosing.h>
#include <slamdunk/optimization/PoseGraphOptimizer.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace slamdunk;

namespace {

/// Keyframe i of a ring of `n` around a circle of radius 2 m, looking outward.
Pose onRing(int i, int n) {
  const double a = 2 * M_PI * i / n;
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2 * std::sin(a), 0, 2 * std::cos(a));
  return T;
}

/// The ring as odometry sees it: each step's rotation off by 0.4 degrees about the vertical.
std::map<KeyframeId, Pose> drifted(int n) {
  std::map<KeyframeId, Pose> out{{0, onRing(0, n)}};
  Pose bias = Pose::Identity();
  bias.linear() = Eigen::AngleAxisd(0.4 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (int i = 1; i < n; ++i)
    out[i] = out[i - 1] * onRing(i - 1, n).inverse() * onRing(i, n) * bias;
  return out;
}

/// A keyframe with no features or edges, as the tracker adds one before linking it.
void addBareKeyframe(KeyframeGraph& graph, KeyframeId id, const Pose& pose) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  graph.addKeyframe(kf, pose);
}

void buildRing(KeyframeGraph& graph, const std::map<KeyframeId, Pose>& poses) {
  for (const auto& [id, pose] : poses) {
    addBareKeyframe(graph, id, pose);
    if (id > 0)
      graph.addMatches(id - 1, id,
                       {PointMatch{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1), 1.0}});
  }
}

double largestError(const KeyframeGraph& graph, int n) {
  double worst = 0;
  for (const auto& [id, pose] : graph.poses())
    worst = std::max(worst, translationDistance(pose, onRing(static_cast<int>(id), n)));
  return worst;
}
}  // namespace

TEST(PoseGraph, OneLoopPullsADriftedRingBackOntoTheTruth) {
  const int n = 40;
  KeyframeGraph graph;
  buildRing(graph, drifted(n));
  const double before = largestError(graph, n);
  ASSERT_GT(before, 0.3);  // the data needs the correction
  // The loop as a place recognition measures it: the last keyframe relative to the first.
  const RelativePoseConstraint loop{0, n - 1, onRing(0, n).inverse() * onRing(n - 1, n)};
  const PoseGraphReport report = optimizePoseGraph(graph, {loop});
  ASSERT_TRUE(report.usable) << report.message;
  EXPECT_EQ(report.vertices, size_t(n));
  EXPECT_EQ(report.constraints, size_t(n));  // n - 1 edges and the loop
  EXPECT_LT(report.finalCost, report.initialCost);
  EXPECT_EQ(graph.pose(0).matrix(), onRing(0, n).matrix());  // the gauge stays
  EXPECT_LT(largestError(graph, n), before / 10);
  EXPECT_GT(report.maxTranslationChange, 0.5 * before);
}

TEST(PoseGraph, KeyframesAddedMeanwhileMoveWithTheNewest) {
  KeyframeGraph graph;
  buildRing(graph, drifted(10));
  const Pose newestBefore = graph.pose(9);
  const Pose newcomerBefore = newestBefore * onRing(0, 10);  // anything, relative to 9
  std::map<KeyframeId, Pose> corrected = graph.poses();
  corrected[9] = onRing(9, 10);
  addBareKeyframe(graph, 10, newcomerBefore);
  graph.applyCorrection(corrected, 9);
  EXPECT_TRUE(graph.pose(9).isApprox(onRing(9, 10)));
  // Keyframe 10 keeps its pose relative to 9.
  EXPECT_TRUE((graph.pose(9).inverse() * graph.pose(10))
                  .isApprox(newestBefore.inverse() * newcomerBefore, 1e-9));
}

// Live, the tracker adds a keyframe to the graph a moment before its edges. A correction whose
// snapshot caught it in between must still carry it with the keyframes it is about to join,
// not leave it where the drift put it (the rest of the ring 0.4 m away).
TEST(PoseGraph, AKeyframeCaughtBeforeItsEdgesMovesWithTheNewestOptimized) {
  const int n = 40;
  KeyframeGraph graph;
  buildRing(graph, drifted(n));
  const Pose lastBefore = graph.pose(n - 1);
  addBareKeyframe(graph, n, lastBefore * onRing(1, n));  // no edge yet
  const Pose edgelessBefore = graph.pose(n);
  const RelativePoseConstraint loop{0, n - 1, onRing(0, n).inverse() * onRing(n - 1, n)};
  ASSERT_TRUE(optimizePoseGraph(graph, {loop}).usable);
  EXPECT_GT(translationDistance(graph.pose(n - 1), lastBefore), 0.3);  // the ring moved
  EXPECT_TRUE((graph.pose(n - 1).inverse() * graph.pose(n))
                  .isApprox(lastBefore.inverse() * edgelessBefore, 1e-9));
}

TEST(PoseGraph, ALoopNamingAnUnknownKeyframeChangesNothing) {
  KeyframeGraph graph;
  buildRing(graph, drifted(5));
  const auto before = graph.poses();
  const PoseGraphReport report = optimizePoseGraph(graph, {{0, 42, Pose::Identity()}});
  EXPECT_FALSE(report.usable);
  EXPECT_NE(report.message.find("does not hold"), std::string::npos);
  for (const auto& [id, pose] : graph.poses()) EXPECT_EQ(pose.matrix(), before.at(id).matrix());
}

bool samePoses(const std::map<KeyframeId, Pose>& a, const std::map<KeyframeId, Pose>& b) {
  if (a.size() != b.size()) return false;
  for (const auto& [id, pose] : a)
    if (!b.count(id) || pose.matrix() != b.at(id).matrix()) return false;
  return true;
}

// Live, a correction is solved beside the tracker and written at once where the caller says
// (between two frames): until then every frame reads the map as it was, and a keyframe the
// tracker added meanwhile moves with the newest keyframe corrected.
TEST(LoopClosing, ACorrectionTouchesTheMapOnlyWhenItIsWritten) {
  const int n = 40;
  auto graph = std::make_shared<KeyframeGraph>();
  buildRing(*graph, drifted(n));
  const std::map<KeyframeId, Pose> before = graph->poses();
  LoopClosing closing(LoopClosingOptions{}, LocalOptimizerOptions{}, TrackerOptions{}, graph);
  LoopHypothesis loop;
  loop.candidate = 0;
  loop.query = n - 1;
  loop.T_candidate_query = onRing(0, n).inverse() * onRing(n - 1, n);

  const double drift = largestError(*graph, n);
  ASSERT_GT(drift, 0.3);  // the data needs the correction

  bool untouchedUntilWritten = false, newcomerFollowed = false;
  double errorWhenWritten = 0;
  closing.correct({loop}, DepthNoiseModel{}, [&](const std::function<void()>& write) {
    untouchedUntilWritten = samePoses(graph->poses(), before);
    addBareKeyframe(*graph, n, graph->pose(n - 1) * onRing(1, n));
    const Pose newcomerRelative = graph->pose(n - 1).inverse() * graph->pose(n);
    write();
    for (int id = 0; id < n; ++id)  // the ring; the newcomer has no place on it
      errorWhenWritten =
          std::max(errorWhenWritten, translationDistance(graph->pose(id), onRing(id, n)));
    newcomerFollowed =
        (graph->pose(n - 1).inverse() * graph->pose(n)).isApprox(newcomerRelative, 1e-9);
  });
  EXPECT_TRUE(untouchedUntilWritten);
  EXPECT_LT(errorWhenWritten, drift / 10);
  EXPECT_TRUE(newcomerFollowed);
  EXPECT_EQ(closing.statistics().loops, 1u);
}
