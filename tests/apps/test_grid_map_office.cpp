// The occupancy grid slamdunk-rawlog makes of the synthetic office tour (--gridmap), checked
// against the office's own geometry: the floor where the office's floor is, occupied cells on
// its walls and boxes, free cells along the path walked; and the files as MRPT reads them.

#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/RigidAlignment.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SlamOptions.h>
#include <slamdunk/synthetic/FloorPlan.h>

#include "TestData.h"

#include <gtest/gtest.h>

#include <iostream>
#include <ostream>

using namespace slamdunk;

namespace {

/// A point of the floor plan, at the scene's ground coordinates (x, z), is on its geometry:
/// inside a box, or within `tolerance` of a wall or a box's footprint on either side.
bool onGeometry(const FloorPlan& plan, double x, double z, double tolerance) {
  const double clearance = plan.clearance(x, z);
  return clearance <= tolerance && (plan.contains(x, z) || clearance >= -tolerance);
}

/// The rigid transform that best puts the keyframes' positions on the ground truth's.
Pose mapInScene(const Trajectory& keyframes, const Trajectory& gt) {
  std::vector<Eigen::Vector3d> map, scene;
  for (const auto& k : keyframes)
    for (const auto& g : gt)
      if (std::abs(g.timestamp - k.timestamp) < 1e-4) {
        map.push_back(k.pose.translation());
        scene.push_back(g.pose.translation());
      }
  return eval::RigidAlignment::compute(map, scene).transform();
}

}  // namespace

struct OfficeRun {
  const char* rawlog;
  bool sharedRun;  ///< the suite's shared run of the rawlog has the grid (shared-runs/<rawlog>)
  FloorPlan plan;
  double cells;          ///< how near a wall or box an occupied cell must lie
  double minOnGeometry;  ///< share of occupied cells that do
  double floorMetres;    ///< how near the floor plan's the grid's floor must lie
};

/// gtest prints the parameter into ctest's test name: the sequence's name, not its bytes.
void PrintTo(const OfficeRun& run, std::ostream* os) { *os << run.rawlog; }

class SlamdunkRawlogGridMap : public ::testing::TestWithParam<OfficeRun> {};

// The whole 55 m ring of the office: with exact depth (tour_twins, whose room C repeats room
// A), and with a Kinect's depth noise and a focal length 3 % off whose drift the loop closure
// corrects (tour_drift). There the map itself is off by its ATE (about 0.1 m) and the 3 % of
// the focal length sideways: its walls lie within 4 cells (20 cm) of the office's, 90 % of its
// occupied cells within 3, and its floor within 5 cm of the office's (3 cm with exact depth).
TEST_P(SlamdunkRawlogGridMap, TheOfficesGridMatchesItsGeometry) {
  REQUIRE_RAWLOG(rawlog, GetParam().rawlog);
  std::string dir, map;
  if (GetParam().sharedRun) {
    REQUIRE_SHARED_RUN_DIR(shared, GetParam().rawlog);
    dir = shared;
    map = dir + "/run.map";
  } else {
    dir = test::scratchDir(std::string("GridMap_") + GetParam().rawlog);
    map = dir + "/office.map";
    const auto run = test::runCommand(
        test::toolPath("slamdunk-rawlog") + " " + test::shellQuote(rawlog) + " -q --trajectory " +
        test::shellQuote(dir + "/trajectory.txt") + " --gridmap " +
        test::shellQuote(dir + "/office") + " --save-map " + test::shellQuote(map));
    ASSERT_EQ(run.exitCode, 0) << run.output;
  }
  const std::string prefix = dir + "/office";

  // The app's grid is the library's on the saved map, cell for cell.
  const auto graph = CKeyframeGraphMap::loadFromFile(map)->graph();
  const GridMap grid = GridMapBuilder(SlamOptions().gridMap).build(*graph);
  const mrpt::maps::COccupancyGridMap2D saved = readGridMap(prefix + ".gridmap");
  ASSERT_EQ(saved.getSizeX(), grid.grid.getSizeX());
  ASSERT_EQ(saved.getSizeY(), grid.grid.getSizeY());
  EXPECT_EQ(saved.getRawMap(), grid.grid.getRawMap());
  mrpt::maps::COccupancyGridMap2D ros;
  ASSERT_TRUE(ros.loadFromROSMapServerYAML(prefix + ".yaml"));
  EXPECT_EQ(ros.getSizeX(), grid.grid.getSizeX());

  // The map's world in the floor plan's (y down, floor at floorY): the keyframes' best fit to
  // the ground truth, so that the map's own drift spreads over the whole office.
  const FloorPlan& plan = GetParam().plan;
  const Trajectory gt = readTumTrajectory(test::groundTruthOf(rawlog));
  const Pose T_scene_floor =
      mapInScene(readTumTrajectory(dir + "/trajectory_keyframes.txt"), gt) * grid.T_world_floor;
  EXPECT_NEAR(T_scene_floor.translation().y(), plan.floorY, GetParam().floorMetres);
  EXPECT_GT(T_scene_floor.linear().col(2).dot(Eigen::Vector3d(0, -1, 0)),
            std::cos(1.0 * M_PI / 180));

  const double res = grid.grid.getResolution();
  size_t occupied = 0, onWalls = 0;
  for (unsigned cy = 0; cy < grid.grid.getSizeY(); ++cy)
    for (unsigned cx = 0; cx < grid.grid.getSizeX(); ++cx) {
      if (grid.cellState(int(cx), int(cy)) != CellState::Occupied) continue;
      const Eigen::Vector3d p =
          T_scene_floor * Eigen::Vector3d(grid.grid.idx2x(cx), grid.grid.idx2y(cy), 0);
      ++occupied;
      onWalls += onGeometry(plan, p.x(), p.z(), (GetParam().cells + 0.5) * res);
    }
  size_t pathCells = 0, pathFree = 0, besideFree = 0;
  const Pose T_floor_scene = T_scene_floor.inverse();
  const auto freeAt = [&](const Eigen::Vector3d& p) {
    return GridMap::stateOf(grid.grid.getPos(float(p.x()), float(p.y()))) == CellState::Free;
  };
  for (size_t i = 0; i + 10 < gt.size(); i += 10) {
    const Eigen::Vector3d c = T_floor_scene * gt[i].pose.translation();
    const Eigen::Vector3d ahead = T_floor_scene * gt[i + 10].pose.translation();
    const Eigen::Vector2d forward = (ahead - c).head<2>().normalized();
    ++pathCells;
    pathFree += freeAt(c);
    besideFree += freeAt(c + 0.5 * Eigen::Vector3d(forward.y(), -forward.x(), 0));
  }

  const double onShare = double(onWalls) / double(occupied);
  const double pathShare = double(pathFree) / double(pathCells);
  const double besideShare = double(besideFree) / double(pathCells);
  std::cout << "office grid: " << grid.grid.getSizeX() << " x " << grid.grid.getSizeY()
            << " cells, " << occupied << " occupied (" << 100 * onShare << " % within "
            << GetParam().cells << " cells of a wall or box), " << grid.freeCells
            << " free; free: " << 100 * pathShare << " % of the path's cells, " << 100 * besideShare
            << " % of those 0.5 m to its right\n";
  EXPECT_GT(occupied, 2000u) << "the office's 149 m of walls are hardly in the grid";
  EXPECT_GE(onShare, GetParam().minOnGeometry);
  EXPECT_GE(pathShare, 0.98);
  // Where the camera looks (27-43 degrees right of its path), by the depth's rays alone.
  EXPECT_GE(besideShare, 0.95);
}

INSTANTIATE_TEST_SUITE_P(
    Office, SlamdunkRawlogGridMap,
    ::testing::Values(OfficeRun{"tour_twins", true, FloorPlan::officeWithTwinRooms(), 1, 0.9, 0.03},
                      OfficeRun{"tour_drift", false, FloorPlan::office(), 4, 0.95, 0.05}),
    [](const auto& info) { return std::string(info.param.rawlog); });
