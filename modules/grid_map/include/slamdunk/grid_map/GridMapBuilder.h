#pragma once
// The 2D occupancy grid a robot plans and localizes on (MRPT's COccupancyGridMap2D), made from
// the keyframes' depth at their optimized poses. The floor comes from the map (FloorPlane.h) or
// from the caller (a robot knows its camera's pose on its base); points between two heights
// above it are obstacles, and each depth reading's ray from its camera marks the cells it
// crosses free at the height it crosses them.

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/grid_map/GridMapOptions.h>

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>

namespace slamdunk {

enum class CellState { Unknown, Free, Occupied };

struct GridMap {
  /// In the floor frame (x, y on the floor). Cells hold MRPT's probability of being free: 0
  /// occupied, 1 free, 0.5 where nothing was seen (stored as log-odds, read back within 0.001).
  mrpt::maps::COccupancyGridMap2D grid;
  /// A cell's state from its probability of being free (ROS map_server's thresholds).
  static CellState stateOf(float freeProbability) {
    return freeProbability < 0.35f   ? CellState::Occupied
           : freeProbability > 0.65f ? CellState::Free
                                     : CellState::Unknown;
  }
  CellState cellState(int x, int y) const { return stateOf(grid.getCell(x, y)); }
  /// The floor frame in the map's world frame: z up, z = 0 on the floor.
  Pose T_world_floor = Pose::Identity();
  size_t keyframes = 0;      ///< keyframes whose depth went into the grid
  size_t occupiedCells = 0;  ///< cells with an obstacle
  size_t freeCells = 0;
};

class GridMapBuilder {
 public:
  /// Throws std::invalid_argument on bad options.
  explicit GridMapBuilder(GridMapOptions options = {});

  /// The floor as options.floor says: from `sensorPose`, the observations' pose of the camera
  /// on the robot (for the map's first keyframe; a fixed mounting), or found in the map. Throws
  /// std::runtime_error when no keyframe kept depth, when the depth shows no floor, or when
  /// floor = sensor_pose and the observations carry none (no pose, or the identity).
  GridMap build(const KeyframeGraph& graph,
                const std::optional<mrpt::poses::CPose3D>& sensorPose = std::nullopt) const;
  /// The floor given: T_world_floor has z up and z = 0 on the floor.
  GridMap buildOnFloor(const KeyframeGraph& graph, const Pose& T_world_floor) const;

  /// The floor frame of a robot whose camera has pose `sensorPose` on it, from the camera's
  /// (optical) pose in the world: the robot's frame, on the floor.
  static Pose floorUnderCamera(const Pose& T_world_camera, const mrpt::poses::CPose3D& sensorPose);

 private:
  struct Views;
  GridMap rasterize(const Views& views, const Pose& T_world_floor) const;

  GridMapOptions options_;
};

}  // namespace slamdunk
