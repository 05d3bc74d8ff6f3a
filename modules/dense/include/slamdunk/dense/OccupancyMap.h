#pragma once
// A coloured 3D occupancy grid (OctoMap ColorOcTree) built by ray casting (paper Sec. 4, last
// paragraph, ref. [11]): each keyframe's decimated depth is inserted as rays from its camera
// centre, so the cells a ray crosses become free and the cell it ends in becomes occupied.
// OctoMap stays inside the implementation: this header does not include it.

#include <slamdunk/dense/DenseReconstruction.h>

#include <Eigen/Core>

#include <memory>
#include <string>

namespace slamdunk {

struct OccupancyMapOptions {
  double resolution = 0.02;  ///< metres, the size of the smallest voxel
  int pixelStride = 8;       ///< decimation of each depth map before ray casting
  double minDepth = 0.3;     ///< metres
  double maxDepth = 4.0;     ///< metres: farther readings are not inserted at all
  bool undistort = true;

  /// Throws std::invalid_argument naming the bad value.
  void validate() const;
};

struct OccupancyStatistics {
  double resolution = 0;
  size_t keyframes = 0;       ///< keyframes inserted
  size_t rays = 0;            ///< depth readings inserted
  size_t occupiedLeaves = 0;  ///< leaves (possibly larger than one voxel after pruning)
  size_t freeLeaves = 0;
  double occupiedVolume = 0;  ///< cubic metres
  double freeVolume = 0;
  Eigen::Vector3d occupiedMin = Eigen::Vector3d::Zero();  ///< bounding box of occupied leaves
  Eigen::Vector3d occupiedMax = Eigen::Vector3d::Zero();
  size_t memoryBytes = 0;
};

class OccupancyMap {
 public:
  /// Throws std::runtime_error when built without OctoMap, std::invalid_argument on bad options.
  explicit OccupancyMap(const OccupancyMapOptions& options = {});
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  /// Ray-casts the keyframe's decimated depth from its camera centre and integrates colours.
  /// A keyframe without depth is ignored.
  void insertKeyframe(const Keyframe& keyframe, const Pose& T_world_keyframe);
  void insertKeyframes(const std::vector<PosedKeyframe>& keyframes);

  OccupancyStatistics statistics() const;
  /// Full colour tree (.ot, ColorOcTree), and binary occupancy only (.bt, what octovis and most
  /// ROS tools read). Both atomic; throw std::runtime_error.
  void writeColourTree(const std::string& path) const;
  void writeBinary(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slamdunk
