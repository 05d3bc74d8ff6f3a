#include <slamdunk/core/IniOptions.h>
#include <slamdunk/grid_map/GridMapOptions.h>

#include <cmath>

namespace slamdunk {

void GridMapOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  loadIniKeys(*this, cfg, section);
  validate(section);
}

void GridMapOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

void GridMapOptions::validate(const std::string& section) const {
  const SectionChecks require(section);
  require(resolution >= 0.005 && resolution <= 1, "resolution must be in [0.005, 1] m");
  require(minObstacleHeight > 0 && std::isfinite(minObstacleHeight),
          "min_obstacle_height must be > 0");
  require(maxObstacleHeight > minObstacleHeight && std::isfinite(maxObstacleHeight),
          "max_obstacle_height must be greater than min_obstacle_height");
  require(maxDepth > 0 && std::isfinite(maxDepth), "max_depth must be > 0");
  require(pixelStride >= 1, "pixel_stride must be >= 1");
}

}  // namespace slamdunk
