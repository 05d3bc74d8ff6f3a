// Live, a loop correction moves the map on the back end's thread and tells the tracker after:
// a frame can be registered in the moved map while the tracker's last pose is still in the old
// one. Such a frame must be tracked, in the moved map, not refused as a jump (nor lost).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/tracking/Tracker.h>

#include "../common/TestData.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace slamdunk;

namespace {

std::vector<RgbdFrame> firstFrames(const std::string& rawlog, size_t count) {
  RawlogReader reader(rawlog);
  std::vector<RgbdFrame> frames;
  while (frames.size() < count)
    if (const auto obs = reader.next())
      frames.push_back(RgbdFrame::fromObservation(*obs));
    else
      break;
  return frames;
}

/// The loop correction: every keyframe moved rigidly by `correction`, as the back end writes it.
void moveEveryKeyframe(KeyframeGraph& graph, const Pose& correction) {
  std::map<KeyframeId, Pose> moved;
  for (const auto& [id, pose] : graph.poses()) moved[id] = orthonormalized(correction * pose);
  graph.applyCorrection(moved, moved.rbegin()->first);
}

}  // namespace

TEST(Tracker, AFrameRegisteredInAMapMovedBeforeTheTrackerIsToldIsTrackedThere) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const size_t frameCount = 60, movedAt = 45;
  const std::vector<RgbdFrame> frames = firstFrames(rawlog, frameCount);
  ASSERT_EQ(frames.size(), frameCount);

  Pose correction = Pose::Identity();  // larger than the tracker's largest plausible jump
  correction.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  correction.translation() = Eigen::Vector3d(1.2, 0.0, -0.4);

  Tracker unmoved(TrackerOptions{}, FeatureOptions{}, std::make_shared<KeyframeGraph>());
  Tracker moved(TrackerOptions{}, FeatureOptions{}, std::make_shared<KeyframeGraph>());
  for (size_t i = 0; i < frameCount; ++i) {
    if (i == movedAt) {
      ASSERT_GT(moved.graph()->keyframeCount(), 1u);
      moveEveryKeyframe(*moved.graph(), correction);
    }
    const TrackingResult expected = unmoved.process(frames[i]);
    const TrackingResult r = moved.process(frames[i]);
    ASSERT_NE(expected.status, TrackingStatus::Lost)
        << "frame " << i << ": " << expected.lostReason;
    ASSERT_NE(r.status, TrackingStatus::Lost) << "frame " << i << ": " << r.lostReason;
    if (i < movedAt) continue;
    EXPECT_FALSE(r.depthOnly) << "frame " << i;
    // In the moved map: where the unmoved run puts it, moved by the correction.
    const Pose there = correction * expected.pose;
    EXPECT_LT(translationDistance(r.pose, there), 0.01) << "frame " << i;
  }
}
