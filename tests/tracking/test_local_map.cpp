// Local Mapping: the window's pool is prepared off the tracking thread and handed over at a
// fixed frame offset (offline) or as soon as it is ready (live); new keyframes are matched from
// the next frame on through an index of their own.

#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/mapping/LocalMap.h>

#include "PoolTestData.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

using namespace slamdunk;

namespace {

using test::randomDescriptors;

/// A keyframe with n random features.
KeyframePtr makeKeyframe(KeyframeId id, int n) {
  return test::makeKeyframe(id, randomDescriptors(n, 100 + id));
}

Pose at(double x) {
  Pose p = Pose::Identity();
  p.translation().x() = x;
  return p;
}

LocalMapOptions options(bool background, int handover, PoolIndexType index = PoolIndexType::Flann) {
  LocalMapOptions o;
  o.backgroundPreparation = background;
  o.handoverFrames = handover;
  o.pool.index = index;
  o.pool.budget = 0;  // every feature: some tests need an index that takes long to build
  return o;
}

/// Adds keyframe `id` to the graph and tells the local map, as the tracker does.
void spawn(KeyframeGraph& graph, LocalMap& map, KeyframeId id, int features, double x) {
  graph.addKeyframe(makeKeyframe(id, features), at(x));
  map.keyframeAdded(id);
}

const CameraIntrinsics K;

}  // namespace

TEST(LocalMap, InlineBuildsTheWindowAtOnce) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap map(options(false, 0), graph);
  map.beginFrame();
  spawn(*graph, map, 0, 300, 0.0);
  EXPECT_FALSE(map.includes(0));  // the window asked for after a keyframe brings it in
  map.beginFrame();
  map.requestWindow(at(0.0), K);
  EXPECT_FALSE(map.windowPending());
  EXPECT_TRUE(map.includes(0));
  EXPECT_EQ(map.pool().size(), 300u);
}

TEST(LocalMap, WindowIsHandedOverExactlyAtTheFixedFrameOffset) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMapOptions o = options(true, 8);
  o.handoverFeaturesPerFrame = 150;  // 400 features: 1 + 400 / 150 = 3 frames after the request
  LocalMap map(o, graph);
  map.beginFrame();
  spawn(*graph, map, 0, 200, 0.0);
  spawn(*graph, map, 1, 200, 0.1);
  map.beginFrame();  // both keyframes' own indexes are due now
  EXPECT_TRUE(map.includes(0));
  EXPECT_TRUE(map.includes(1));
  EXPECT_EQ(map.pool().size(), 400u);
  EXPECT_EQ(map.pool().parts().size(), 2u);

  map.requestWindow(at(0.05), K);
  EXPECT_TRUE(map.windowPending());
  // However soon the worker is done, the window waits for its frame (determinism).
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  map.beginFrame();
  map.beginFrame();
  EXPECT_TRUE(map.windowPending());
  EXPECT_EQ(map.pool().parts().size(), 2u);
  map.beginFrame();  // the third frame after the request
  EXPECT_FALSE(map.windowPending());
  ASSERT_EQ(map.pool().parts().size(), 1u);  // one index over both keyframes
  EXPECT_EQ(map.pool().size(), 400u);
  EXPECT_TRUE(map.includes(0));
  EXPECT_TRUE(map.includes(1));
}

TEST(LocalMap, SmallWindowIsHandedOverAtTheNextFrameAndLargeOnesAtTheCap) {
  for (const auto& [perFrame, expectedFrames] : {std::pair{3000, 1}, std::pair{10, 4}}) {
    auto graph = std::make_shared<KeyframeGraph>();
    LocalMapOptions o = options(true, 4);  // at most 4 frames
    o.handoverFeaturesPerFrame = perFrame;
    LocalMap map(o, graph);
    map.beginFrame();
    spawn(*graph, map, 0, 200, 0.0);
    spawn(*graph, map, 1, 200, 0.1);
    map.beginFrame();
    map.requestWindow(at(0.05), K);
    int frames = 0;
    while (map.windowPending() && frames < 10) {
      map.beginFrame();
      ++frames;
    }
    EXPECT_EQ(frames, expectedFrames) << perFrame << " features per frame";
    EXPECT_EQ(map.pool().parts().size(), 1u);
  }
}

TEST(LocalMap, KeyframesSpawnedAfterTheSnapshotStayInThePool) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap map(options(true, 2), graph);
  map.beginFrame();
  spawn(*graph, map, 0, 200, 0.0);
  map.beginFrame();
  map.requestWindow(at(0.0), K);  // snapshot: keyframe 0 only
  spawn(*graph, map, 1, 150, 0.1);
  map.beginFrame();
  EXPECT_TRUE(map.includes(1));
  map.beginFrame();  // the window over keyframe 0 replaces keyframe 0's own index
  EXPECT_FALSE(map.windowPending());
  EXPECT_EQ(map.pool().size(), 350u);
  EXPECT_EQ(map.pool().parts().size(), 2u);
  EXPECT_TRUE(map.includes(0));
  EXPECT_TRUE(map.includes(1));
}

TEST(LocalMap, WaitsForADueWindowThatIsNotReadyYet) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap map(options(true, 1), graph);
  map.beginFrame();
  for (KeyframeId id = 0; id < 40; ++id) spawn(*graph, map, id, 1000, 0.01 * id);
  map.requestWindow(at(0.0), K);  // 40,000 features: tens of ms to index
  map.beginFrame();               // due now: waits for it
  EXPECT_FALSE(map.windowPending());
  EXPECT_EQ(map.pool().size(), 40000u);
  EXPECT_EQ(map.statistics().windowMs.size(), 1u);
}

TEST(LocalMap, LiveNeverWaitsAndTakesThePoolWhenReady) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap map(options(true, 0), graph);
  map.beginFrame();
  for (KeyframeId id = 0; id < 40; ++id) spawn(*graph, map, id, 1000, 0.01 * id);
  map.requestWindow(at(0.0), K);
  const auto t = std::chrono::steady_clock::now();
  double waited = map.beginFrame();
  EXPECT_EQ(waited, 0.0);
  // Polled like frames at 100 Hz: the window arrives within a few seconds, never blocking.
  for (int frame = 0; frame < 500 && map.windowPending(); ++frame) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    waited += map.beginFrame();
  }
  EXPECT_EQ(waited, 0.0);
  EXPECT_FALSE(map.windowPending());
  EXPECT_EQ(map.pool().size(), 40000u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(), 5.0);
}

TEST(LocalMap, SplitPoolMatchesLikeOneIndex) {
  // Window index + a new keyframe's own index give the same matches as one index over both
  // (exact search, so any difference would be the merge's).
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap split(options(true, 1, PoolIndexType::Exact), graph);
  split.beginFrame();
  spawn(*graph, split, 0, 300, 0.0);
  split.beginFrame();
  split.requestWindow(at(0.0), K);
  spawn(*graph, split, 1, 300, 0.1);
  split.beginFrame();
  ASSERT_EQ(split.pool().parts().size(), 2u);

  FeaturePoolOptions exact;
  exact.index = PoolIndexType::Exact;
  FeaturePool whole(exact);
  whole.build(*graph, {0, 1}, at(0.0), K);
  ASSERT_EQ(whole.size(), split.pool().size());

  cv::Mat query;
  // Keyframe 0 keeps half floats since the window was asked for, keyframe 1 floats.
  cv::vconcat(matchableDescriptors(graph->keyframe(0)->features.descriptors).rowRange(0, 150),
              matchableDescriptors(graph->keyframe(1)->features.descriptors).rowRange(0, 150),
              query);
  query += 0.02 * randomDescriptors(300, 9);
  const auto a = split.pool().match(query, 0.8), b = whole.match(query, 0.8);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(a.size(), 280u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].query, b[i].query);
    EXPECT_EQ(split.pool().feature(a[i].pool).keyframe, whole.feature(b[i].pool).keyframe);
    EXPECT_EQ(split.pool().feature(a[i].pool).index, whole.feature(b[i].pool).index);
    // One index over both keyframes bounds d1 by its k-th neighbour when no feature of the same
    // keyframe is among the k; a keyframe's own index always finds one: never a larger ratio.
    EXPECT_LE(a[i].ratio, b[i].ratio + 1e-12);
  }
}

// Keyframes keep their descriptors as half floats, and as 8-bit codes far beyond the window (a
// quarter of the memory); a return there matches them as it would the floats.
TEST(LocalMap, KeyframesKeepCompactDescriptors) {
  for (const bool half : {true, false})
    for (const double beyond : {1.0, -1.0}) {
      SCOPED_TRACE("compact_beyond " + std::to_string(beyond) + ", half floats " +
                   std::to_string(half));
      auto graph = std::make_shared<KeyframeGraph>();
      LocalMapOptions o = options(false, 0, PoolIndexType::Exact);
      o.compactBeyond = beyond;
      o.halfFloatDescriptors = half;
      LocalMap map(o, graph);
      map.beginFrame();
      spawn(*graph, map, 0, 300, 0.0);
      spawn(*graph, map, 1, 300, 3.4);  // within W / 2 + 1 m of the window at 0
      spawn(*graph, map, 2, 300, 10.0);
      const cv::Mat floats = graph->keyframe(2)->features.descriptors.clone();
      map.requestWindow(at(0.0), K);
      const int near = half ? CV_16FC1 : CV_32FC1;
      EXPECT_EQ(graph->keyframe(0)->features.descriptors.type(), near);
      EXPECT_EQ(graph->keyframe(1)->features.descriptors.type(), near);
      const cv::Mat& far = graph->keyframe(2)->features.descriptors;
      ASSERT_EQ(far.type(), beyond < 0 ? near : CV_8SC1);
      EXPECT_EQ(far.total() * far.elemSize(), 300u * 64 * (beyond < 0 ? (half ? 2 : 4) : 1));

      // Back there: the window's pool finds each feature of keyframe 2 again, and its codes
      // stay codes (never made half floats again).
      map.requestWindow(at(10.0), K);
      ASSERT_TRUE(map.includes(2));
      EXPECT_EQ(graph->keyframe(2)->features.descriptors.type(), beyond < 0 ? near : CV_8SC1);
      const cv::Mat query = floats.rowRange(0, 200) + 0.02 * randomDescriptors(200, 9);
      size_t found = 0;
      for (const PoolMatch& m : map.pool().match(query, 0.8)) {
        const PoolFeature& f = map.pool().feature(m.pool);
        found += f.keyframe == 2 && f.index == m.query;
      }
      EXPECT_GE(found, 196u);
    }
}

TEST(LocalMap, ShiftIsMeasuredFromTheWindowAskedForLast) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMap map(options(true, 3), graph);
  map.beginFrame();
  spawn(*graph, map, 0, 100, 0.0);
  map.requestWindow(at(0.0), K);
  EXPECT_FALSE(map.shiftNeeded(at(0.2)));
  EXPECT_TRUE(map.shiftNeeded(at(0.3)));  // T = 0.25 m
  map.requestWindow(at(0.3), K);          // pending, but no second request for the same shift
  EXPECT_FALSE(map.shiftNeeded(at(0.35)));
}

// The pool keeps what the window's orientation sees (frustum filter): turning on the spot moves
// the window too, past windowShiftAngle (7 degrees by default); 0 is the paper's test alone.
TEST(LocalMap, TurningMovesTheWindowToo) {
  auto graph = std::make_shared<KeyframeGraph>();
  LocalMapOptions o = options(true, 3);
  LocalMap map(o, graph);
  map.beginFrame();
  spawn(*graph, map, 0, 100, 0.0);
  map.requestWindow(at(0.0), K);
  auto turned = [](double deg) {
    Pose p = at(0.0);
    p.linear() = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    return p;
  };
  EXPECT_FALSE(map.shiftNeeded(turned(6)));
  EXPECT_TRUE(map.shiftNeeded(turned(8)));
  o.windowShiftAngle = 0;
  LocalMap paper(o, graph);
  paper.requestWindow(at(0.0), K);
  EXPECT_FALSE(paper.shiftNeeded(turned(90)));
}

TEST(LocalMap, SameRequestsGiveTheSamePool) {
  auto run = [] {
    auto graph = std::make_shared<KeyframeGraph>();
    LocalMap map(options(true, 2), graph);
    map.beginFrame();
    for (KeyframeId id = 0; id < 6; ++id) {
      spawn(*graph, map, id, 500, 0.1 * id);
      map.beginFrame();
      map.requestWindow(at(0.1 * id), K);
    }
    for (int i = 0; i < 3; ++i) map.beginFrame();
    return map.pool().match(randomDescriptors(400, 77), 0.95);
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].query, b[i].query);
    EXPECT_EQ(a[i].pool, b[i].pool);
  }
}
