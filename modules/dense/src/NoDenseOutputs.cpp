// Built instead of PclCloudIo.cpp and OccupancyMap.cpp when SLAMDUNK_WITH_DENSE is OFF: the
// dense cloud and the renderer still work (with this file's voxel filter), file outputs say why
// they are missing.

#include <slamdunk/dense/DenseReconstruction.h>
#include <slamdunk/dense/OccupancyMap.h>

#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace slamdunk {

namespace {
[[noreturn]] void notBuilt(const std::string& what) {
  throw std::runtime_error(what +
                           ": this build has no dense outputs (configure with "
                           "-DSLAMDUNK_WITH_DENSE=ON, needs PCL and OctoMap)");
}
}  // namespace

bool haveDenseFileOutputs() { return false; }

DenseCloud voxelFilter(const DenseCloud& cloud, double voxelSize) {
  if (!(voxelSize > 0)) throw std::invalid_argument("voxel filter: voxel size must be > 0");
  // Same as PCL's VoxelGrid: voxels aligned on multiples of the size, centroid and mean colour.
  struct Acc {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
    size_t n = 0, order = 0;
  };
  const auto key = [&](const Eigen::Vector3f& p) {
    const auto q = (p.cast<double>() / voxelSize).array().floor().cast<int64_t>();
    return uint64_t(q.x() & 0x1FFFFF) | uint64_t(q.y() & 0x1FFFFF) << 21 |
           uint64_t(q.z() & 0x1FFFFF) << 42;
  };
  std::unordered_map<uint64_t, Acc> voxels;
  for (size_t i = 0; i < cloud.size(); ++i) {
    Acc& a = voxels.try_emplace(key(cloud.points[i]), Acc{{0, 0, 0}, {0, 0, 0}, 0, voxels.size()})
                 .first->second;
    a.sum += cloud.points[i].cast<double>();
    a.rgb += Eigen::Vector3d(cloud.colours[i][0], cloud.colours[i][1], cloud.colours[i][2]);
    ++a.n;
  }
  DenseCloud out;
  out.points.resize(voxels.size());
  out.colours.resize(voxels.size());
  for (const auto& [k, a] : voxels) {
    out.points[a.order] = (a.sum / double(a.n)).cast<float>();
    const Eigen::Vector3d c = (a.rgb / double(a.n)).array().round();
    out.colours[a.order] = {uint8_t(c.x()), uint8_t(c.y()), uint8_t(c.z())};
  }
  return out;
}

void writePly(const DenseCloud&, const std::string& path, bool) { notBuilt("writing " + path); }
void writePcd(const DenseCloud&, const std::string& path, bool) { notBuilt("writing " + path); }
DenseCloud readPointCloud(const std::string& path) { notBuilt("reading " + path); }

struct OccupancyMap::Impl {};
OccupancyMap::OccupancyMap(const OccupancyMapOptions&) { notBuilt("occupancy map"); }
OccupancyMap::~OccupancyMap() = default;
void OccupancyMap::insertKeyframe(const Keyframe&, const Pose&) {}
void OccupancyMap::insertKeyframes(const std::vector<PosedKeyframe>&) {}
OccupancyStatistics OccupancyMap::statistics() const { return {}; }
void OccupancyMap::writeColourTree(const std::string& path) const { notBuilt("writing " + path); }
void OccupancyMap::writeBinary(const std::string& path) const { notBuilt("writing " + path); }

}  // namespace slamdunk
