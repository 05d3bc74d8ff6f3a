#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/grid_map/GridMapFiles.h>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace slamdunk {

namespace {

// map_server's trinary image: black occupied, near-white free, grey unknown.
constexpr uint8_t kOccupiedPixel = 0, kFreePixel = 254, kUnknownPixel = 205;

void writeBytes(const std::string& path, const std::string& bytes) {
  AtomicOutput atomic(path);
  {
    std::ofstream f(atomic.tempPath(), std::ios::binary);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    f.close();
    if (!f) throw std::runtime_error(writeErrorMessage(path, "write failed", atomic.tempPath()));
  }
  atomic.commit();
}

std::string pngOf(const mrpt::maps::COccupancyGridMap2D& grid) {
  const int nx = int(grid.getSizeX()), ny = int(grid.getSizeY());
  cv::Mat image(ny, nx, CV_8UC1);
  for (int y = 0; y < ny; ++y) {
    uint8_t* row = image.ptr<uint8_t>(ny - 1 - y);  // the image's top row is the largest y
    for (int x = 0; x < nx; ++x) {
      const CellState state = GridMap::stateOf(grid.getCell(x, y));
      row[x] = state == CellState::Occupied ? kOccupiedPixel
               : state == CellState::Free   ? kFreePixel
                                            : kUnknownPixel;
    }
  }
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("PNG encoding failed");
  return std::string(bytes.begin(), bytes.end());
}

std::string yamlOf(const GridMap& map, const std::string& imageName) {
  const Eigen::Quaterniond q(map.T_world_floor.linear());
  const Eigen::Vector3d& t = map.T_world_floor.translation();
  std::ostringstream s;
  s << std::setprecision(9);
  s << "# Occupancy grid made by SlamDunk from its keyframe map (ROS map_server format).\n"
    << "# The grid lies on the floor (z = 0, z up, x forward, y left); the floor frame in the\n"
    << "# map's world frame (the first camera's optical frame), TUM order tx ty tz qx qy qz qw:\n"
    << "# floor_in_world: [" << t.x() << ", " << t.y() << ", " << t.z() << ", " << q.x() << ", "
    << q.y() << ", " << q.z() << ", " << q.w() << "]\n"
    << "image: " << imageName << "\n"
    << "resolution: " << map.grid.getResolution() << "\n"
    << "origin: [" << map.grid.getXMin() << ", " << map.grid.getYMin() << ", 0.0]\n"
    << "negate: 0\n"
    << "occupied_thresh: 0.65\n"
    << "free_thresh: 0.196\n";
  return s.str();
}

}  // namespace

const std::vector<std::string>& gridMapExtensions() {
  static const std::vector<std::string> extensions{".gridmap", ".png", ".yaml"};
  return extensions;
}

void writeGridMap(const GridMap& map, const std::string& prefix, std::string imageName) {
  if (imageName.empty()) imageName = std::filesystem::path(prefix + ".png").filename().string();
  writeGzArchive(prefix + ".gridmap", map.grid);
  writeBytes(prefix + ".png", pngOf(map.grid));
  writeBytes(prefix + ".yaml", yamlOf(map, imageName));
}

mrpt::maps::COccupancyGridMap2D readGridMap(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("grid map file '" + path + "' does not exist or is not a file");
  mrpt::io::CFileGZInputStream f;
  if (!f.open(path)) throw std::runtime_error("cannot open grid map file '" + path + "'");
  mrpt::maps::COccupancyGridMap2D grid;
  try {
    auto in = mrpt::serialization::archiveFrom(f);
    in >> grid;
  } catch (const std::exception&) {
    throw std::runtime_error("grid map file '" + path +
                             "' does not hold an MRPT COccupancyGridMap2D");
  }
  return grid;
}

}  // namespace slamdunk
