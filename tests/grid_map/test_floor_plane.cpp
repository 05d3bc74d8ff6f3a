// The floor found from points of a room seen by tilted cameras: under a table top that holds
// more points than the floor, and in a world frame that is the first camera's.

#include <slamdunk/grid_map/FloorPlane.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

using namespace slamdunk;

namespace {

/// A camera `height` above the floor of a z-up room, turned `yawDeg` about the vertical and
/// pitched down `pitchDeg`: its optical frame (x right, y down, z forward) in the room.
Pose cameraInRoom(double x, double y, double height, double yawDeg, double pitchDeg) {
  Eigen::Matrix3d level;  // optical axes for a camera looking along room +x
  level.col(0) = Eigen::Vector3d(0, -1, 0);
  level.col(1) = Eigen::Vector3d(0, 0, -1);
  level.col(2) = Eigen::Vector3d(1, 0, 0);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yawDeg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               level * Eigen::AngleAxisd(-pitchDeg * M_PI / 180, Eigen::Vector3d::UnitX());
  T.translation() = Eigen::Vector3d(x, y, height);
  return T;
}

void addGrid(std::vector<Eigen::Vector3d>& pts, double x0, double x1, double y0, double y1,
             double z, double step) {
  for (double x = x0; x <= x1; x += step)
    for (double y = y0; y <= y1; y += step) pts.emplace_back(x, y, z);
}

struct RoomPoints {
  std::vector<Eigen::Vector3f> inFirstCamera;
  std::vector<Pose> cameras;  ///< in the first camera's frame
  Pose T_room_first;
};

/// The floor (z = 0) sparse, a table top at 0.75 m dense, two walls; seen from three cameras
/// 1.4 m high pitched down 20-40 degrees, everything expressed in the first camera's frame.
RoomPoints roomWithTable() {
  std::vector<Eigen::Vector3d> pts;
  addGrid(pts, -1, 4, -2, 2, 0.0, 0.08);           // floor: about 3,200 points
  addGrid(pts, 1.5, 2.7, -0.6, 0.6, 0.75, 0.012);  // table: about 10,000 points
  for (double y = -2; y <= 2; y += 0.05)
    for (double z = 0; z <= 2.5; z += 0.05)
      pts.emplace_back(4, y, z), pts.emplace_back(y + 1, 2, z);
  RoomPoints r;
  r.T_room_first = cameraInRoom(0, 0, 1.4, 10, 35);
  const Pose first = r.T_room_first.inverse();
  for (const auto& p : pts) r.inFirstCamera.push_back((first * p).cast<float>());
  for (const Pose& c :
       {r.T_room_first, cameraInRoom(0.5, 0.5, 1.3, -20, 20), cameraInRoom(1, -0.5, 1.5, 30, 40)})
    r.cameras.push_back(first * c);
  return r;
}

}  // namespace

TEST(FloorPlane, FindsTheFloorUnderATableThatHoldsMorePoints) {
  const RoomPoints room = roomWithTable();
  const auto floor = findFloor(room.inFirstCamera, room.cameras);
  ASSERT_TRUE(floor);
  const Pose T_room_floor = room.T_room_first * floor->T_world_floor;
  // Up is the room's up, the origin is on the floor below the first camera...
  EXPECT_GT(T_room_floor.linear().col(2).dot(Eigen::Vector3d::UnitZ()), std::cos(0.5 * M_PI / 180));
  EXPECT_NEAR(T_room_floor.translation().z(), 0, 0.01);
  EXPECT_NEAR(T_room_floor.translation().x(), 0, 0.01);
  EXPECT_NEAR(T_room_floor.translation().y(), 0, 0.01);
  // ...and x is the first camera's heading (yaw 10 degrees) along the floor.
  EXPECT_NEAR(std::atan2(T_room_floor.linear()(1, 0), T_room_floor.linear()(0, 0)) * 180 / M_PI, 10,
              0.5);
  EXPECT_GT(floor->supportingPoints, 1000u);
}

TEST(FloorPlane, TheSameInputsGiveTheSameFrame) {
  const RoomPoints room = roomWithTable();
  const auto a = findFloor(room.inFirstCamera, room.cameras);
  const auto b = findFloor(room.inFirstCamera, room.cameras);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->T_world_floor.isApprox(b->T_world_floor, 0));
}

TEST(FloorPlane, NothingWhenTheCamerasNeverSawAFloor) {
  RoomPoints room = roomWithTable();
  std::vector<Eigen::Vector3f> wallOnly;
  const Pose first = room.T_room_first.inverse();
  for (double y = -2; y <= 2; y += 0.02)
    for (double z = 0.5; z <= 2.5; z += 0.02)
      wallOnly.push_back((first * Eigen::Vector3d(4, y, z)).cast<float>());
  EXPECT_FALSE(findFloor(wallOnly, room.cameras));
  EXPECT_FALSE(findFloor({}, room.cameras));
  EXPECT_FALSE(findFloor(room.inFirstCamera, {}));
}
