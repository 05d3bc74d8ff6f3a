#include <slamdunk/synthetic/SyntheticScene.h>
#include <slamdunk/synthetic/SyntheticTrajectory.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace slamdunk;

namespace {

/// Angle between the camera's "down" (optical +y) and gravity (world +y): roll and pitch.
double tiltFromGravityDeg(const Pose& T_w_opt) {
  const Eigen::Vector3d down = T_w_opt.linear().col(1);
  return std::acos(std::clamp(down.y(), -1.0, 1.0)) / kDeg;
}

/// Roll: rotation of the image about the optical axis relative to the horizon.
double rollDeg(const Pose& T_w_opt) {
  const Eigen::Vector3d right = T_w_opt.linear().col(0);
  return std::asin(std::clamp(right.y(), -1.0, 1.0)) / kDeg;
}

}  // namespace

TEST(SyntheticTrajectory, NamesAndDefaults) {
  EXPECT_TRUE(SyntheticTrajectory::isKnown("sweep"));
  EXPECT_TRUE(SyntheticTrajectory::isKnown("loop"));
  EXPECT_FALSE(SyntheticTrajectory::isKnown("nope"));
  EXPECT_EQ(SyntheticTrajectory::generate("sweep").size(), 150u);
  EXPECT_EQ(SyntheticTrajectory::generate("loop").size(), 400u);
  EXPECT_EQ(SyntheticTrajectory::generate("loop", 37).size(), 37u);
  EXPECT_THROW(SyntheticTrajectory::generate("nope"), std::invalid_argument);
  EXPECT_THROW(SyntheticTrajectory::generate("nope", 10), std::invalid_argument);
  EXPECT_THROW(SyntheticTrajectory::generate("loop", 1), std::invalid_argument);
  EXPECT_THROW(SyntheticTrajectory::generate("loop", -5), std::invalid_argument);
}

TEST(SyntheticTrajectory, ThirtyHertzStamps) {
  const auto traj = SyntheticTrajectory::generate("sweep");
  ASSERT_GT(traj.front().timestamp, 0.0);  // MRPT treats time 0 as invalid
  for (size_t i = 1; i < traj.size(); ++i)
    EXPECT_NEAR(traj[i].timestamp - traj[i - 1].timestamp, 1.0 / 30, 2e-6);  // whole microseconds
}

TEST(SyntheticTrajectory, LoopReturnsToItsStart) {
  const auto traj = SyntheticTrajectory::generate("loop");
  EXPECT_LT(translationDistance(traj.front().pose, traj.back().pose), 0.01);
  EXPECT_LT(rotationDistance(traj.front().pose, traj.back().pose) / kDeg, 0.5);
  // ... after really going somewhere: half way round it is ~2 m away, facing the other way.
  const auto& mid = traj[traj.size() / 2].pose;
  EXPECT_GT(translationDistance(traj.front().pose, mid), 1.8);
  EXPECT_GT(rotationDistance(traj.front().pose, mid) / kDeg, 150);
  const auto st = SyntheticTrajectory::stats(traj);
  EXPECT_NEAR(st.pathLength, 2 * M_PI, 0.3);
  EXPECT_NEAR(st.totalRotationDeg, 360, 30);
}

TEST(SyntheticTrajectory, HandHeldSpeedsAndSmoothness) {
  for (const std::string name : {"sweep", "loop"}) {
    SCOPED_TRACE(name);
    const auto traj = SyntheticTrajectory::generate(name);
    const auto st = SyntheticTrajectory::stats(traj);
    EXPECT_LE(st.maxSpeed, 0.5);
    EXPECT_LE(st.maxAngularSpeedDeg, 40);
    // Smooth: the velocity changes little from one frame to the next (no jumps).
    for (size_t i = 2; i < traj.size(); ++i) {
      const Eigen::Vector3d v1 = traj[i - 1].pose.translation() - traj[i - 2].pose.translation();
      const Eigen::Vector3d v2 = traj[i].pose.translation() - traj[i - 1].pose.translation();
      ASSERT_LT((v2 - v1).norm(), 0.002) << "frame " << i;
    }
  }
  const auto sweep = SyntheticTrajectory::stats(SyntheticTrajectory::generate("sweep"));
  EXPECT_GT(sweep.pathLength, 0.3);  // "a few tens of cm"
  EXPECT_LT(sweep.pathLength, 0.8);
  EXPECT_GT(sweep.totalRotationDeg, 20);
}

TEST(SyntheticTrajectory, NearlyLevelAndInsideTheRoomAwayFromBoxes) {
  const RoomLayout room;
  // Boxes as in SyntheticScene (geometry is independent of the seed); a footprint test with
  // the box's bounding circle is enough for a clearance check.
  const SyntheticScene scene(1, false);
  for (const std::string name : {"sweep", "loop"}) {
    SCOPED_TRACE(name);
    for (const auto& sp : SyntheticTrajectory::generate(name)) {
      const Eigen::Vector3d p = sp.pose.translation();
      ASSERT_LT(tiltFromGravityDeg(sp.pose), 20);
      ASSERT_LT(std::abs(rollDeg(sp.pose)), 5);
      ASSERT_GT(p.x(), room.xMin + 1.0);
      ASSERT_LT(p.x(), room.xMax - 1.0);
      ASSERT_GT(p.z(), room.zMin + 1.0);
      ASSERT_LT(p.z(), room.zMax - 1.0);
      ASSERT_NEAR(p.y(), 0.0, 0.1);  // camera height 1.3 m above the floor
      for (const auto& b : scene.boxes()) {
        const double r = 0.5 * std::hypot(b.sizeX, b.sizeZ);
        ASSERT_GT(std::hypot(p.x() - b.x, p.z() - b.z) - r, 0.5);
      }
    }
  }
}
