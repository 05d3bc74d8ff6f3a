// The occupancy grid from keyframes whose depth images are computed exactly from a few boxes:
// walls, a low crate and a shelf above a robot's height, seen from cameras 1.3 m up.

#include <slamdunk/grid_map/GridMapBuilder.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/slam/SlamOptions.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <limits>

using namespace slamdunk;

namespace {

/// An axis-aligned box of a z-up room (metres).
struct Box {
  Eigen::Vector3d lo, hi;
};

/// A corridor 2 m wide along +x closed by a wall at x = 3: walls 10 cm thick from the floor to
/// 2.5 m, a crate 0.4 m high at x 1.8-2.2, y -0.2-0.2, and a shelf at 2.0-2.1 m at x 1-1.4.
const std::vector<Box>& corridor() {
  static const std::vector<Box> boxes{
      {{-1, -1.1, -0.1}, {3.1, 1.1, 0}},     // floor
      {{-1, -1.1, 2.5}, {3.1, 1.1, 2.6}},    // ceiling
      {{-1, 1.0, 0}, {3.1, 1.1, 2.5}},       // left wall (y = 1)
      {{-1, -1.1, 0}, {3.1, -1.0, 2.5}},     // right wall (y = -1)
      {{3.0, -1.1, 0}, {3.1, 1.1, 2.5}},     // end wall (x = 3)
      {{-1.1, -1.1, 0}, {-1.0, 1.1, 2.5}},   // back wall
      {{1.8, -0.2, 0}, {2.2, 0.2, 0.4}},     // crate
      {{1.0, -1.0, 2.0}, {1.4, 1.0, 2.1}}};  // shelf above the robot's height
  return boxes;
}

/// Distance along the ray to the nearest box (slab test), or infinity.
double castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : corridor()) {
    double t0 = 0, t1 = best;
    for (int a = 0; a < 3; ++a) {
      const double inv = 1 / dir[a];
      double near = (b.lo[a] - origin[a]) * inv, far = (b.hi[a] - origin[a]) * inv;
      if (near > far) std::swap(near, far);
      t0 = std::max(t0, near), t1 = std::min(t1, far);
    }
    if (t0 <= t1 && t0 > 1e-9) best = t0;
  }
  return best;
}

/// A camera at (x, y, 1.3) looking along room `yawDeg`, pitched down 30 degrees (level, it
/// would see the floor only beyond 2.8 m): its optical frame in the room.
Pose camera(double x, double y, double yawDeg) {
  Eigen::Matrix3d level;
  level.col(0) = Eigen::Vector3d(0, -1, 0);
  level.col(1) = Eigen::Vector3d(0, 0, -1);
  level.col(2) = Eigen::Vector3d(1, 0, 0);
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yawDeg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               level * Eigen::AngleAxisd(-30 * M_PI / 180, Eigen::Vector3d::UnitX());
  T.translation() = Eigen::Vector3d(x, y, 1.3);
  return T;
}

/// A keyframe whose subsampled depth (stride 4) is the corridor seen from T_room_camera.
KeyframePtr keyframeSeeing(KeyframeId id, const Pose& T_room_camera) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  kf->depthSmallStride = 4;
  kf->depthSmall = cv::Mat(120, 160, CV_32F);
  const CameraIntrinsics& K = kf->intrinsics;
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 160; ++c) {
      const Eigen::Vector3d ray = K.backProject(c * 4, r * 4, 1.0);  // z = 1: depth = t
      const double t = castRay(T_room_camera.translation(), T_room_camera.linear() * ray);
      kf->depthSmall.at<float>(r, c) = std::isfinite(t) ? float(t) : 0.f;
    }
  return kf;
}

/// Two keyframes, one at the corridor's start looking down it and one turned 30 degrees to the
/// left, in the first one's frame (the map's world).
struct CorridorMap {
  KeyframeGraph graph;
  Pose T_room_world;
};

std::unique_ptr<CorridorMap> corridorMap() {
  auto map = std::make_unique<CorridorMap>();
  const std::vector<Pose> cameras{camera(-0.5, 0, 0), camera(0, 0.3, 30), camera(0, -0.3, -30)};
  map->T_room_world = cameras.front();
  for (KeyframeId id = 0; id < cameras.size(); ++id)
    map->graph.addKeyframe(keyframeSeeing(id, cameras[id]),
                           cameras.front().inverse() * cameras[id]);
  return map;
}

/// The state of the grid's cell at room point (x, y).
CellState cellAt(const GridMap& m, const Pose& T_room_world, double x, double y) {
  const Eigen::Vector3d p = (T_room_world * m.T_world_floor).inverse() * Eigen::Vector3d(x, y, 0);
  return GridMap::stateOf(m.grid.getPos(float(p.x()), float(p.y())));
}

/// An obstacle's face may fall on a cell boundary: its readings land on either side.
bool occupiedNear(const GridMap& m, const Pose& T_room_world, double x, double y) {
  const double r = m.grid.getResolution();
  for (double dx : {-r, 0.0, r})
    for (double dy : {-r, 0.0, r})
      if (cellAt(m, T_room_world, x + dx, y + dy) == CellState::Occupied) return true;
  return false;
}

}  // namespace

TEST(GridMapBuilder, WallsAndACrateAreOccupiedTheFloorBetweenIsFree) {
  const auto map = corridorMap();
  const GridMap m = GridMapBuilder().build(map->graph);
  const Pose& T = map->T_room_world;
  EXPECT_EQ(m.keyframes, 3u);
  // The floor found is the room's: z = 0 below the first camera, z up.
  const Pose T_room_floor = T * m.T_world_floor;
  EXPECT_NEAR(T_room_floor.translation().z(), 0, 0.01);
  EXPECT_GT(T_room_floor.linear().col(2).z(), std::cos(0.5 * M_PI / 180));

  for (double y : {-0.6, 0.0, 0.6}) EXPECT_TRUE(occupiedNear(m, T, 3.0, y)) << y;
  for (double x : {0.5, 1.5, 2.6}) {
    EXPECT_TRUE(occupiedNear(m, T, x, 1.0)) << x;
    EXPECT_TRUE(occupiedNear(m, T, x, -1.0)) << x;
  }
  EXPECT_TRUE(occupiedNear(m, T, 1.8, 0.0)) << "the crate's front";
  for (double x : {0.5, 1.2, 2.6})  // under the shelf too: it is above the robot
    for (double y : {-0.6, 0.0, 0.6})
      EXPECT_EQ(cellAt(m, T, x, y), CellState::Free) << x << " " << y;
  EXPECT_EQ(cellAt(m, T, 3.5, 0.0), CellState::Unknown) << "behind the end wall nothing is known";
  EXPECT_GT(m.freeCells, m.occupiedCells);
}

TEST(GridMapBuilder, AGivenFloorIsUsedAsIs) {
  const auto map = corridorMap();
  // The floor 10 cm higher than it is: the crate still rises above it.
  Pose floor = map->T_room_world.inverse();
  floor.translation() += map->T_room_world.inverse().linear() * Eigen::Vector3d(0, 0, 0.1);
  const GridMap m = GridMapBuilder().buildOnFloor(map->graph, floor);
  EXPECT_TRUE(m.T_world_floor.isApprox(floor));
  EXPECT_TRUE(occupiedNear(m, map->T_room_world, 1.8, 0.0));
}

// A robot's camera: its observations say where it sits on the robot (1.3 m up, pitched down
// 30 degrees), and the robot's frame is on the floor.
TEST(GridMapBuilder, TheFloorUnderARobotsCameraComesFromItsSensorPose) {
  const auto map = corridorMap();
  const mrpt::poses::CPose3D onRobot(0, 0, 1.3, 0, mrpt::DEG2RAD(30.0), 0);
  const Pose T_room_robot =
      map->T_room_world * GridMapBuilder::floorUnderCamera(Pose::Identity(), onRobot);
  // The first camera is at (-0.5, 0, 1.3) looking along room x: its robot at (-0.5, 0, 0).
  EXPECT_LT((T_room_robot.translation() - Eigen::Vector3d(-0.5, 0, 0)).norm(), 1e-9);
  EXPECT_TRUE(T_room_robot.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-9));

  const GridMap fromRobot = GridMapBuilder().build(map->graph, onRobot);
  EXPECT_TRUE((map->T_room_world * fromRobot.T_world_floor).isApprox(T_room_robot, 1e-9));
  EXPECT_TRUE(occupiedNear(fromRobot, map->T_room_world, 1.8, 0.0));

  // floor = map ignores the sensor pose; floor = sensor_pose without one is an error.
  GridMapOptions o;
  o.floor = GridFloor::Map;
  const GridMap fitted = GridMapBuilder(o).build(map->graph, onRobot);
  EXPECT_LT((fitted.T_world_floor.translation() - fromRobot.T_world_floor.translation()).norm(),
            0.01);
  o.floor = GridFloor::SensorPose;
  for (const auto& none : {std::optional<mrpt::poses::CPose3D>(),
                           std::optional<mrpt::poses::CPose3D>(mrpt::poses::CPose3D())}) {
    try {
      GridMapBuilder(o).build(map->graph, none);
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("sensor_pose"), std::string::npos) << e.what();
    }
  }
}

TEST(GridMapBuilder, AMapWithoutDepthIsAClearError) {
  KeyframeGraph graph;
  auto kf = std::make_shared<Keyframe>();
  graph.addKeyframe(kf, Pose::Identity());
  try {
    GridMapBuilder().build(graph);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("kept its depth"), std::string::npos) << e.what();
  }
}

TEST(GridMapBuilder, BadOptionsNameTheKey) {
  GridMapOptions o;
  o.maxObstacleHeight = 0.05;
  try {
    GridMapBuilder{o};
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_obstacle_height"), std::string::npos) << e.what();
  }
  mrpt::config::CConfigFileMemory ini("[grid_map]\nresolution = 0.1\nheight = 2\n");
  SlamOptions s;
  try {
    s.loadFromConfigFile(ini, "");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("height"), std::string::npos) << e.what();
  }
  mrpt::config::CConfigFileMemory good("[grid_map]\nresolution = 0.1\n");
  s.loadFromConfigFile(good, "");
  EXPECT_EQ(s.gridMap.resolution, 0.1);
}

TEST(GridMapFiles, MrptReadsBothTheGridmapAndTheRosMapItsCellsAgree) {
  const auto map = corridorMap();
  const GridMap m = GridMapBuilder().build(map->graph);
  const std::string dir = test::scratchDir("GridMapFiles");
  writeGridMap(m, dir + "/corridor");
  for (const char* ext : {".gridmap", ".png", ".yaml"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/corridor" + ext)) << ext;

  const mrpt::maps::COccupancyGridMap2D read = readGridMap(dir + "/corridor.gridmap");
  ASSERT_EQ(read.getSizeX(), m.grid.getSizeX());
  ASSERT_EQ(read.getSizeY(), m.grid.getSizeY());
  EXPECT_EQ(read.getRawMap(), m.grid.getRawMap());
  EXPECT_FLOAT_EQ(read.getXMin(), m.grid.getXMin());

  mrpt::maps::COccupancyGridMap2D ros;
  ASSERT_TRUE(ros.loadFromROSMapServerYAML(dir + "/corridor.yaml"));
  ASSERT_EQ(ros.getSizeX(), m.grid.getSizeX());
  ASSERT_EQ(ros.getSizeY(), m.grid.getSizeY());
  EXPECT_NEAR(ros.getXMin(), m.grid.getXMin(), 1e-4);
  EXPECT_NEAR(ros.getYMin(), m.grid.getYMin(), 1e-4);
  size_t differ = 0;
  for (unsigned y = 0; y < m.grid.getSizeY(); ++y)
    for (unsigned x = 0; x < m.grid.getSizeX(); ++x)
      differ += GridMap::stateOf(ros.getCell(int(x), int(y))) != m.cellState(int(x), int(y));
  EXPECT_EQ(differ, 0u);
}

TEST(GridMapFiles, ReadingSomethingElseNamesTheFile) {
  const std::string dir = test::scratchDir("GridMapFilesBad");
  std::ofstream(dir + "/bad.gridmap") << "not a grid";
  for (const std::string& path : {dir + "/bad.gridmap", dir + "/missing.gridmap"}) {
    try {
      readGridMap(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}
