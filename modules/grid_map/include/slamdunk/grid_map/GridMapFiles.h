#pragma once
// A GridMap on disk, as robot software exchanges it: MRPT's own serialized grid (.gridmap, what
// MRPT's apps such as pf-localization load), and ROS map_server's PNG with its YAML
// (resolution, origin), which MRPT reads too (COccupancyGridMap2D::loadFromROSMapServerYAML).

#include <slamdunk/grid_map/GridMapBuilder.h>

#include <string>
#include <vector>

namespace slamdunk {

/// The extensions writeGridMap() appends to its prefix.
const std::vector<std::string>& gridMapExtensions();

/// Writes PREFIX.gridmap, PREFIX.png and PREFIX.yaml, each atomically. The YAML names its image
/// `imageName` (default: PREFIX.png's file name; a caller writing under a temporary prefix
/// gives the final one) and says in comments where the grid lies in the map's world frame.
/// Throws std::runtime_error naming the file that cannot be written.
void writeGridMap(const GridMap& map, const std::string& prefix, std::string imageName = {});

/// Reads a .gridmap file. Throws std::runtime_error naming the file when it is missing or holds
/// something else.
mrpt::maps::COccupancyGridMap2D readGridMap(const std::string& path);

}  // namespace slamdunk
