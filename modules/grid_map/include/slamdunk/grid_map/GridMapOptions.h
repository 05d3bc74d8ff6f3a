#pragma once
// Section [grid_map]: the 2D occupancy grid a robot navigates on (GridMapBuilder).

#include <slamdunk/core/EnumNames.h>

#include <mrpt/config/CLoadableOptions.h>

#include <string>

namespace slamdunk {

/// Where the floor comes from. A camera on a robot has its pose on the robot in its
/// observations (CObservation3DRangeScan::sensorPose), and the robot's frame lies on the floor,
/// as MRPT's 2D robots have it; a hand-held camera's observations hold none (identity), and the
/// floor is found in the map's depth (FloorPlane.h).
enum class GridFloor { Auto, Map, SensorPose };
SLAMDUNK_ENUM_NAMES(GridFloor, {{GridFloor::Auto, "auto"},
                                {GridFloor::Map, "map"},
                                {GridFloor::SensorPose, "sensor_pose"}});

struct GridMapOptions : public mrpt::config::CLoadableOptions {
  /// auto: the observations' sensor pose when they carry one, else the floor found in the map.
  GridFloor floor = GridFloor::Auto;
  double resolution = 0.05;  ///< metres per cell
  /// Points this high above the floor or higher, up to max_obstacle_height, are obstacles. Lower
  /// ones are the floor: a Kinect's depth noise at 4 m is about 5 cm.
  double minObstacleHeight = 0.10;
  /// The robot's height: what is higher (ceiling, lamps, the top of a door) does not block it.
  double maxObstacleHeight = 1.80;
  double maxDepth = 4.0;  ///< metres: farther depth readings are too noisy to place
  int pixelStride = 2;    ///< of each keyframe's subsampled depth (depthSmall)

  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("floor", o.floor);
    k("resolution", o.resolution);
    k("min_obstacle_height", o.minObstacleHeight);
    k("max_obstacle_height", o.maxObstacleHeight);
    k("max_depth", o.maxDepth);
    k("pixel_stride", o.pixelStride);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
  /// Throws std::invalid_argument naming the section when a value is out of range.
  void validate(const std::string& section = "grid_map") const;
};

}  // namespace slamdunk
