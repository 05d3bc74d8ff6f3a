// The only translation unit that includes OctoMap.

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/dense/OccupancyMap.h>

#include <octomap/ColorOcTree.h>
#include <octomap/octomap.h>

#include <fstream>
#include <iomanip>
#include <limits>
#include <stdexcept>

namespace slamdunk {

struct OccupancyMap::Impl {
  explicit Impl(const OccupancyMapOptions& o) : options(o), tree(o.resolution) {}
  /// Inner nodes (occupancy and colour) are updated lazily: once before any query or write
  /// instead of after every ray.
  void sync() {
    if (!dirty) return;
    tree.updateInnerOccupancy();
    dirty = false;
  }
  OccupancyMapOptions options;
  octomap::ColorOcTree tree;
  size_t keyframes = 0, rays = 0;
  bool dirty = false;
};

OccupancyMap::OccupancyMap(const OccupancyMapOptions& options) {
  options.validate();
  impl_ = std::make_unique<Impl>(options);
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::insertKeyframe(const Keyframe& keyframe, const Pose& T_world_keyframe) {
  if (keyframe.depth.empty()) return;
  const auto& o = impl_->options;
  DenseOptions d;
  d.pixelStride = o.pixelStride;
  d.minDepth = o.minDepth;
  d.maxDepth = o.maxDepth;
  d.undistort = o.undistort;
  d.voxelSize = 0;
  const DenseCloud cloud = backProjectKeyframe(keyframe, T_world_keyframe, d);
  octomap::Pointcloud scan;
  scan.reserve(cloud.size());
  for (const auto& p : cloud.points) scan.push_back(p.x(), p.y(), p.z());
  const Eigen::Vector3d c = T_world_keyframe.translation();
  const octomap::point3d origin(float(c.x()), float(c.y()), float(c.z()));
  // discretize: rays ending in the same voxel are cast once, a large speed-up for dense depth.
  impl_->tree.insertPointCloud(scan, origin, /*maxrange=*/-1, /*lazy_eval=*/true,
                               /*discretize=*/true);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    const auto& rgb = cloud.colours[i];
    impl_->tree.integrateNodeColor(p.x(), p.y(), p.z(), rgb[0], rgb[1], rgb[2]);
  }
  impl_->dirty = true;
  ++impl_->keyframes;
  impl_->rays += cloud.size();
}

void OccupancyMap::insertKeyframes(const std::vector<PosedKeyframe>& keyframes) {
  for (const auto& pk : keyframes)
    if (pk.keyframe) insertKeyframe(*pk.keyframe, pk.pose);
}

OccupancyStatistics OccupancyMap::statistics() const {
  impl_->sync();
  const auto& tree = impl_->tree;
  OccupancyStatistics s;
  s.resolution = tree.getResolution();
  s.keyframes = impl_->keyframes;
  s.rays = impl_->rays;
  s.memoryBytes = tree.memoryUsage();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const double size = it.getSize();
    if (tree.isNodeOccupied(*it)) {
      ++s.occupiedLeaves;
      s.occupiedVolume += size * size * size;
      const Eigen::Vector3d centre(it.getX(), it.getY(), it.getZ());
      const Eigen::Vector3d half = Eigen::Vector3d::Constant(size / 2);
      lo = lo.cwiseMin(centre - half);
      hi = hi.cwiseMax(centre + half);
    } else {
      ++s.freeLeaves;
      s.freeVolume += size * size * size;
    }
  }
  if (s.occupiedLeaves > 0) {
    s.occupiedMin = lo;
    s.occupiedMax = hi;
  }
  return s;
}

void OccupancyMap::writeColourTree(const std::string& path) const {
  impl_->sync();
  AtomicOutput out(path);
  // Through our own stream: OctoMap's write(filename) reports only a failed open, not a failed
  // write (a full disk would leave a truncated .ot behind).
  std::ofstream f(out.tempPath(), std::ios::binary);
  if (!f || !impl_->tree.write(f))
    throw std::runtime_error("cannot write OctoMap file '" + path + "'");
  f.close();
  if (!f) throw std::runtime_error("cannot write OctoMap file '" + path + "'");
  out.commit();
}

void OccupancyMap::writeBinary(const std::string& path) const {
  impl_->sync();
  AtomicOutput out(path);
  // The header of AbstractOccupancyOcTree::writeBinaryConst, but with the plain "OcTree" id:
  // the bits are the same for any occupancy tree, and tools that read .bt files (octovis,
  // octomap_server, OcTree::readBinary) expect an OcTree. writeBinaryData thresholds the
  // current log-odds without altering the colour tree (writeBinary would prune it first).
  std::ofstream f(out.tempPath(), std::ios::binary);
  f << "# Octomap OcTree binary file\n# written by SlamDunk from a ColorOcTree\nid OcTree\n"
    << "size " << impl_->tree.size() << "\n"
    << std::setprecision(17) << "res " << impl_->tree.getResolution() << "\ndata\n";
  impl_->tree.writeBinaryData(f);
  f.close();
  if (!f) throw std::runtime_error("cannot write OctoMap file '" + path + "'");
  out.commit();
}

}  // namespace slamdunk
