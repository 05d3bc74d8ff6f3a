// The large synthetic environment: the "office" floor plan (four rooms joined by corridors into a
// ring) and the "tour" trajectory round it, for scale benchmarks. Geometry is checked without
// rendering; a handful of rendered frames check what the camera sees.

#include <slamdunk/synthetic/FloorPlan.h>
#include <slamdunk/synthetic/RoundedLoop.h>
#include <slamdunk/synthetic/SyntheticRenderer.h>
#include <slamdunk/synthetic/SyntheticScene.h>
#include <slamdunk/synthetic/SyntheticSequence.h>
#include <slamdunk/synthetic/SyntheticTrajectory.h>

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "KeypointSpread.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

using namespace slamdunk;

namespace {

/// Nothing nearer than this to the camera, in any direction: a surface at distance d is seen
/// at z-depth >= d / 1.26 (the image corner's ray is 1.26 times longer than its z), so 0.6 m
/// keeps everything in view beyond 0.47 m, clear of the renderer's 0.4 m near clip (nothing
/// is cut open) and of the 0.3 m a depth camera needs.
constexpr double kMinClearance = 0.6;

/// Into the solid side of a wall (away from the free space).
Eigen::Vector2d outwardNormal(const WallPanel& w) {
  const Eigen::Vector2d right = Eigen::Vector2d(w.x1 - w.x0, w.z1 - w.z0).normalized();
  return {-right.y(), right.x()};  // right = (n.z, -n.x) in the yaw convention
}

std::string pointKey(double x, double z) {
  std::ostringstream ss;
  ss << std::lround(x * 1e6) << "," << std::lround(z * 1e6);
  return ss.str();
}

/// Ground-parallel direction of the optical axis, as a yaw in degrees.
double viewYawDeg(const Pose& T_w_opt) {
  const Eigen::Vector3d axis = T_w_opt.linear().col(2);
  return std::atan2(axis.x(), axis.z()) / kDeg;
}

double wrapDeg(double a) { return std::remainder(a, 360.0); }

}  // namespace

TEST(FloorPlan, RoomIsTheSingleRoomOfRoomLayout) {
  const RoomLayout r;
  const FloorPlan room = FloorPlan::room();
  EXPECT_EQ(room.name, "room");
  ASSERT_EQ(room.areas.size(), 1u);
  EXPECT_EQ(room.areas[0].xMin, r.xMin);
  EXPECT_EQ(room.areas[0].zMax, r.zMax);
  EXPECT_EQ(room.floorY, r.floorY);
  EXPECT_EQ(room.ceilingY, r.ceilingY);
  EXPECT_EQ(room.boxes.size(), 12u);
  // Its hand-listed walls are the ones wallsAround() derives (in another order).
  auto key = [](const WallPanel& w) { return pointKey(w.x0, w.z0) + "->" + pointKey(w.x1, w.z1); };
  std::vector<std::string> listed, derived;
  for (const auto& w : room.walls) listed.push_back(key(w));
  for (const auto& w : wallsAround(room.areas)) derived.push_back(key(w));
  std::sort(listed.begin(), listed.end());
  std::sort(derived.begin(), derived.end());
  EXPECT_EQ(listed, derived);
}

TEST(FloorPlan, WallsEncloseTheFreeSpace) {
  // Perimeter of the free space: the room's 7 x 6 m; the office's four rooms less two 2.4 m
  // doors each, plus both sides of two 9 m and two 7 m corridors.
  for (const auto& [name, perimeter] :
       std::vector<std::pair<std::string, double>>{{"room", 26.0}, {"office", 148.8}}) {
    SCOPED_TRACE(name);
    const FloorPlan plan = FloorPlan::named(name);
    double total = 0;
    std::map<std::string, int> starts, ends;
    for (const auto& w : plan.walls) {
      ASSERT_GT(w.length(), 0.1);
      total += w.length();
      ++starts[pointKey(w.x0, w.z0)];
      ++ends[pointKey(w.x1, w.z1)];
      // Free space in front of the wall, void behind it.
      const Eigen::Vector2d mid((w.x0 + w.x1) / 2, (w.z0 + w.z1) / 2);
      const Eigen::Vector2d n = outwardNormal(w);
      const Eigen::Vector2d front = mid - 0.01 * n, behind = mid + 0.01 * n;
      EXPECT_TRUE(plan.contains(front.x(), front.y())) << "wall at " << mid.transpose();
      EXPECT_FALSE(plan.contains(behind.x(), behind.y())) << "wall at " << mid.transpose();
    }
    EXPECT_NEAR(total, perimeter, 1e-9);
    // Closed: every wall ends where exactly one other begins, so no gap shows the void.
    EXPECT_EQ(starts, ends);
    for (const auto& [point, count] : starts) EXPECT_EQ(count, 1) << point;
  }
  EXPECT_THROW(FloorPlan::named("nope"), std::invalid_argument);
}

TEST(FloorPlan, ClearanceIsTheDistanceToWallsAndBoxes) {
  FloorPlan plan;
  plan.areas = {{"a", 0, 4, 0, 2}};
  plan.walls = wallsAround(plan.areas);
  plan.boxes = {{3, 1, 0.4, 0.5, 0.4, 0, 1.3}};
  EXPECT_NEAR(plan.clearance(1, 1), 1.0, 1e-12);    // walls on three sides at 1 m
  EXPECT_NEAR(plan.clearance(2.5, 1), 0.3, 1e-12);  // the box's face
  EXPECT_NEAR(plan.clearance(3, 1), -0.2, 1e-12);   // inside the box
  EXPECT_NEAR(plan.clearance(5, 1), -1.0, 1e-12);   // outside the walls
  plan.boxes[0].yawDeg = 45;                        // a corner now points at (3.28, 1)
  EXPECT_NEAR(plan.clearance(3.5, 1), 0.5 - 0.2 * std::sqrt(2.0), 1e-12);
  // Two areas may share an edge (no wall between them) but not overlap.
  EXPECT_EQ(wallsAround({{"a", 0, 2, 0, 2}, {"b", 2, 4, 0, 2}}).size(), 4u);
  EXPECT_THROW(wallsAround({{"a", 0, 2, 0, 2}, {"b", 1, 3, 1, 3}}), std::invalid_argument);
  EXPECT_THROW(wallsAround({{"empty", 0, 0, 0, 2}}), std::invalid_argument);
}

TEST(FloorPlan, OfficeBoxesStandInsideClearOfTheWalls) {
  const FloorPlan office = FloorPlan::office();
  EXPECT_EQ(office.areas.size(), 8u);
  EXPECT_GE(office.boxes.size(), 30u);  // clutter in every room and corridor
  for (const auto& b : office.boxes) {
    SCOPED_TRACE("box at " + std::to_string(b.x) + ", " + std::to_string(b.z));
    const double c = std::cos(b.yawDeg * kDeg), s = std::sin(b.yawDeg * kDeg);
    for (const double lx : {-b.sizeX / 2, b.sizeX / 2}) {
      for (const double lz : {-b.sizeZ / 2, b.sizeZ / 2}) {
        const double x = b.x + c * lx + s * lz, z = b.z - s * lx + c * lz;
        EXPECT_TRUE(office.contains(x, z));
        // Not touching a wall (coplanar faces would flicker between the two textures).
        double toWall = 1e9;
        for (const auto& w : office.walls) {
          const Eigen::Vector2d p(x, z), a(w.x0, w.z0), ab(w.x1 - w.x0, w.z1 - w.z0);
          const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
          toWall = std::min(toWall, (p - a - t * ab).norm());
        }
        EXPECT_GT(toWall, 0.01);
      }
    }
    EXPECT_GT(b.baseY - b.sizeY, office.ceilingY + 0.5);  // well below the ceiling
  }
}

// Room C of the twin office is room A turned half a turn about the office's centre: every wall
// of C repeats the texture of the A wall the turn brings onto it (same length, same ends), its
// boxes are A's turned, and nothing else differs from the office.
TEST(FloorPlan, TwinRoomsRepeatRoomATurnedHalfATurn) {
  const FloorPlan office = FloorPlan::office();
  const FloorPlan twins = FloorPlan::officeWithTwinRooms();
  const auto c = OfficeLayout{}.roomCentres();
  const Eigen::Vector2d centre = (c[0] + c[2]) / 2;
  auto turned = [&](double x, double z) -> Eigen::Vector2d {
    return 2 * centre - Eigen::Vector2d(x, z);
  };
  ASSERT_EQ(twins.walls.size(), office.walls.size());
  int repeated = 0;
  for (size_t i = 0; i < twins.walls.size(); ++i) {
    const WallPanel& w = twins.walls[i];
    EXPECT_EQ(w.x0, office.walls[i].x0);
    EXPECT_EQ(w.z1, office.walls[i].z1);
    if (w.textureOf < 0) continue;
    ++repeated;
    const WallPanel& a = twins.walls[size_t(w.textureOf)];
    EXPECT_LT((turned(a.x0, a.z0) - Eigen::Vector2d(w.x0, w.z0)).norm(), 1e-9) << i;
    EXPECT_LT((turned(a.x1, a.z1) - Eigen::Vector2d(w.x1, w.z1)).norm(), 1e-9) << i;
    EXPECT_LT(std::abs(a.length() - w.length()), 1e-9) << i;
  }
  EXPECT_GE(repeated, 4) << "room C has at least four walls";
  ASSERT_EQ(twins.boxes.size(), office.boxes.size());
  for (size_t i = 0; i < twins.boxes.size(); ++i) {
    const RoomBox& b = twins.boxes[i];
    if (i < 16 || i >= 24) {
      EXPECT_EQ(b.x, office.boxes[i].x) << i;
      EXPECT_EQ(b.textureOf, -1) << i;
      continue;
    }
    const RoomBox& a = twins.boxes[i - 16];
    EXPECT_EQ(b.textureOf, static_cast<int>(i - 16));
    EXPECT_LT((turned(a.x, a.z) - Eigen::Vector2d(b.x, b.z)).norm(), 1e-9) << i;
    EXPECT_DOUBLE_EQ(b.yawDeg, a.yawDeg + 180) << i;
    EXPECT_DOUBLE_EQ(b.baseY, a.baseY) << i;
  }
}

TEST(RoundedLoop, RoundedSquare) {
  // 4 m square, corners rounded with 1 m arcs: 4 x 2 m straight + a full 1 m circle.
  const RoundedLoop square({{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 1.0);
  EXPECT_NEAR(square.length(), 8 + 2 * M_PI, 1e-12);
  auto expectPoint = [&](double d, double x, double z, double headingDeg) {
    const auto p = square.at(d);
    EXPECT_NEAR(p.position.x(), x, 1e-12) << "distance " << d;
    EXPECT_NEAR(p.position.y(), z, 1e-12) << "distance " << d;
    EXPECT_NEAR(wrapDeg(p.headingDeg - headingDeg), 0, 1e-9) << "distance " << d;
  };
  expectPoint(0, 1, 0, 90);  // leaving corner 0's arc along +x
  expectPoint(2, 3, 0, 90);
  expectPoint(2 + M_PI / 4, 3 + std::sqrt(0.5), 1 - std::sqrt(0.5), 45);  // mid-arc, turning left
  expectPoint(2 + M_PI / 2, 4, 1, 0);                                     // now along +z
  expectPoint(square.length(), 1, 0, 90);                                 // periodic
  expectPoint(-M_PI / 4, 1 - std::sqrt(0.5), 1 - std::sqrt(0.5), 135);    // before the start
  EXPECT_THROW(RoundedLoop({{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 2.5), std::invalid_argument);
  EXPECT_THROW(RoundedLoop({{0, 0}, {4, 0}}, 1.0), std::invalid_argument);
}

TEST(SyntheticTrajectory, TourIsALongClosedLoopAtWalkingPace) {
  EXPECT_TRUE(SyntheticTrajectory::isKnown("tour"));
  EXPECT_EQ(SyntheticTrajectory::sceneOf("tour"), "office");
  EXPECT_EQ(SyntheticTrajectory::sceneOf("loop"), "room");
  EXPECT_EQ(SyntheticTrajectory::sceneOf("sweep"), "room");
  EXPECT_THROW(SyntheticTrajectory::sceneOf("nope"), std::invalid_argument);
  const int frames = SyntheticTrajectory::defaultFrames("tour");
  EXPECT_GE(frames, 3000);
  EXPECT_LE(frames, 3600);

  const auto traj = SyntheticTrajectory::generate("tour");
  ASSERT_EQ(traj.size(), size_t(frames));
  const auto st = SyntheticTrajectory::stats(traj);
  std::printf(
      "[ tour ] %zu frames, %.1f s, %.2f m, max %.2f m/s, max %.1f deg/s, %.0f deg turned\n",
      st.frames, st.duration, st.pathLength, st.maxSpeed, st.maxAngularSpeedDeg,
      st.totalRotationDeg);
  EXPECT_GE(st.pathLength, 50.0);
  // Closed: the last pose is the first.
  EXPECT_LT(translationDistance(traj.front().pose, traj.back().pose), 0.001);
  EXPECT_LT(rotationDistance(traj.front().pose, traj.back().pose) / kDeg, 0.1);
  // ... after going somewhere: half way round it is across the ring.
  EXPECT_GT(translationDistance(traj.front().pose, traj[traj.size() / 2].pose), 10.0);
  // One lap of left turns: the view turns once round, whatever it wobbles on the way.
  double netTurnDeg = 0;
  for (size_t i = 1; i < traj.size(); ++i)
    netTurnDeg += wrapDeg(viewYawDeg(traj[i].pose) - viewYawDeg(traj[i - 1].pose));
  EXPECT_NEAR(netTurnDeg, -360, 1e-6);

  // Walking pace throughout, smooth turns, no jumps.
  EXPECT_LE(st.maxAngularSpeedDeg, 40);
  for (size_t i = 1; i < traj.size(); ++i) {
    const double speed =
        translationDistance(traj[i - 1].pose, traj[i].pose) * SyntheticTrajectory::kFrameRate;
    ASSERT_GE(speed, 0.4) << "frame " << i;
    ASSERT_LE(speed, 0.6) << "frame " << i;
    if (i < 2) continue;
    const Eigen::Vector3d v1 = traj[i - 1].pose.translation() - traj[i - 2].pose.translation();
    const Eigen::Vector3d v2 = traj[i].pose.translation() - traj[i - 1].pose.translation();
    ASSERT_LT((v2 - v1).norm(), 0.002) << "frame " << i;
  }
}

TEST(SyntheticTrajectory, TourStaysClearOfWallsAndBoxes) {
  const FloorPlan office = FloorPlan::office();
  double minClearance = 1e9;
  for (const auto& sp : SyntheticTrajectory::generate("tour")) {
    const Eigen::Vector3d p = sp.pose.translation();
    const double clearance = office.clearance(p.x(), p.z());
    minClearance = std::min(minClearance, clearance);
    ASSERT_GE(clearance, kMinClearance) << "at " << p.transpose();
    ASSERT_NEAR(office.floorY - p.y(), 1.3, 0.05);  // hand-held height
    // Nearly level: a few degrees of roll and pitch wobble about a slight downward look.
    const Eigen::Vector3d down = sp.pose.linear().col(1), right = sp.pose.linear().col(0);
    ASSERT_LT(std::acos(std::clamp(down.y(), -1.0, 1.0)) / kDeg, 20);
    ASSERT_LT(std::abs(std::asin(std::clamp(right.y(), -1.0, 1.0))) / kDeg, 5);
  }
  std::printf("[ tour ] nearest wall or box: %.2f m\n", minClearance);
}

TEST(SyntheticTrajectory, TourLooksAtTheWallsNotDownTheCorridors) {
  // Always 20-50 degrees to the right of the direction of travel: towards the outer walls.
  const auto traj = SyntheticTrajectory::generate("tour");
  for (size_t i = 0; i + 1 < traj.size(); ++i) {
    const Eigen::Vector3d v = traj[i + 1].pose.translation() - traj[i].pose.translation();
    const double travelYaw = std::atan2(v.x(), v.z()) / kDeg;
    const double offset = wrapDeg(viewYawDeg(traj[i].pose) - travelYaw);
    ASSERT_GT(offset, 20) << "frame " << i;
    ASSERT_LT(offset, 50) << "frame " << i;
  }
}

TEST(SyntheticTrajectory, RoomTrajectoriesAreUnchanged) {
  // Poses of the ground-truth files written before the office existed (TUM precision).
  struct Pinned {
    std::string name;
    size_t frame;
    double t[3], q[4];  // x y z, qx qy qz qw
  };
  const std::vector<Pinned> pinned = {
      {"sweep", 0, {-0.2, 0, 0.2}, {-0.12120173, 0.103749324, 0.0127388152, 0.98710888}},
      {"sweep",
       75,
       {0.00210841239, -0.0399977772, 0.275790655},
       {-0.12077983, -0.0294641787, -0.0206509277, 0.992027033}},
      {"sweep", 149, {0.2, 0, 0.35}, {-0.12036893, -0.155268426, -0.0190645655, 0.980326261}},
      {"loop", 0, {0, 0, -1}, {-0.0371931916, 0.955900283, 0.138806881, 0.256132709}},
      {"loop",
       100,
       {0.999992251, -0.0299979077, 0.00393682273},
       {-0.0952380425, 0.493860813, 0.0346611186, 0.863614393}},
      {"loop",
       200,
       {-0.00787358444, -0.000708564027, 0.999969003},
       {-0.138793757, -0.259155501, -0.0380757295, 0.955052333}},
  };
  for (const auto& p : pinned) {
    const auto traj = SyntheticTrajectory::generate(p.name);
    const Pose expected =
        poseFromTranslationQuaternion(p.t[0], p.t[1], p.t[2], p.q[0], p.q[1], p.q[2], p.q[3]);
    EXPECT_LT(translationDistance(traj[p.frame].pose, expected), 1e-8)
        << p.name << " frame " << p.frame;
    EXPECT_LT(rotationDistance(traj[p.frame].pose, expected), 1e-7)
        << p.name << " frame " << p.frame;
  }
}

TEST(SyntheticSequence, TourFramesSeeTexturedSurfacesEverywhere) {
  // Six frames spread along the lap (corridors and rooms): the closed office fills the view,
  // nothing is nearer than a depth camera's minimum, and the textures give many keypoints in
  // every part of the image (as the room's TexturesGiveManyWellSpreadKeypoints asks).
  SyntheticOptions o;
  o.trajectory = "tour";
  SyntheticSequence seq(o);
  EXPECT_EQ(seq.scene().plan().name, "office");
  for (int k = 0; k < 6; ++k) {
    const size_t i = (2 * k + 1) * seq.size() / 12;
    cv::Mat bgr, depth;
    seq.renderImages(i, bgr, depth);
    const double valid = double(cv::countNonZero(depth > 0)) / depth.total();
    double nearest = 0, farthest = 0;
    cv::minMaxLoc(depth, &nearest, &farthest, nullptr, nullptr, depth > 0);
    const test::KeypointSpread spread = test::keypointSpread(bgr);
    const Eigen::Vector3d p = seq.groundTruth()[i].pose.translation();
    std::printf(
        "[ tour frame ] %zu at (%.1f, %.1f): %.1f%% valid depth, %.2f-%.2f m, %zu ORB "
        "keypoints, %d/16 cells\n",
        i, p.x(), p.z(), 100 * valid, nearest, farthest, spread.keypoints, spread.occupiedCells);
    EXPECT_GE(valid, 0.9) << "frame " << i;
    EXPECT_GE(nearest, 0.3) << "frame " << i;
    EXPECT_GT(spread.keypoints, 300u) << "frame " << i;
    EXPECT_GE(spread.occupiedCells, 12) << "frame " << i;
  }
}

TEST(FloorPlan, ABareAreaIsPaintedAlmostPlainWithItsWalls) {
  const FloorPlan office = FloorPlan::office();
  const FloorPlan bare = FloorPlan::withBareArea(office, "corridor B-C", 0.02);
  ASSERT_EQ(bare.walls.size(), office.walls.size());
  const FloorArea* corridor = nullptr;
  for (const FloorArea& a : bare.areas) {
    if (a.name == "corridor B-C") corridor = &a;
    EXPECT_EQ(a.textureDetail, a.name == "corridor B-C" ? 0.02 : 1.0) << a.name;
  }
  ASSERT_NE(corridor, nullptr);
  double bareLength = 0;
  for (const WallPanel& w : bare.walls) {
    if (w.textureDetail == 1.0) continue;
    bareLength += w.length();
    for (const auto& [x, z] : {std::pair{w.x0, w.z0}, std::pair{w.x1, w.z1}}) {
      EXPECT_TRUE(std::abs(x - corridor->xMin) < 1e-9 || std::abs(x - corridor->xMax) < 1e-9);
      EXPECT_GE(z, corridor->zMin - 1e-9);
      EXPECT_LE(z, corridor->zMax + 1e-9);
    }
  }
  // Its two long sides, nothing of the rooms it joins.
  EXPECT_NEAR(bareLength, 2 * (corridor->zMax - corridor->zMin), 1e-9);
  EXPECT_EQ(bare.boxes.size(), office.boxes.size());
  EXPECT_THROW(FloorPlan::withBareArea(office, "corridor A-C", 0.1), std::invalid_argument);
  EXPECT_EQ(bare.name, "office with a bare corridor B-C");
  // The option paints the office's corridor: a path through another scene is refused.
  SyntheticOptions o;
  o.trajectory = "loop";
  o.bareCorridor = true;
  EXPECT_THROW(SyntheticSequence{o}, std::invalid_argument);
}
