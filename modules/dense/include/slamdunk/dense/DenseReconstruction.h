#pragma once
// Dense reconstruction by back-projection (paper Sec. 4, last paragraph): every keyframe that
// kept its images contributes its depth map, placed with the keyframe's current (optimised)
// pose and coloured from its colour image; a voxel grid then merges the overlapping views.

#include <slamdunk/dense/DenseCloud.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <string>
#include <vector>

namespace slamdunk {

struct DenseOptions {
  int pixelStride = 2;      ///< use every n-th pixel in both directions (1 = all)
  double minDepth = 0.3;    ///< metres; closer readings are sensor noise
  double maxDepth = 4.0;    ///< metres; farther Kinect-type readings are too noisy to keep
  double voxelSize = 0.01;  ///< metres; 0 keeps every back-projected point
  bool undistort = true;    ///< remove lens distortion with the keyframe's intrinsics

  /// Throws std::invalid_argument naming the bad value.
  void validate() const;
};

/// A keyframe and the pose (T_world_keyframe, optical frame) to place it with.
struct PosedKeyframe {
  KeyframePtr keyframe;
  Pose pose = Pose::Identity();
};

/// The graph's keyframes that kept a depth image, with their current poses, in id order.
std::vector<PosedKeyframe> keyframesWithImages(const KeyframeGraph& graph);

/// One keyframe's depth back-projected into the world (no voxel filter). Keyframes without
/// colour get a neutral grey; a grey-only image gives grey levels.
DenseCloud backProjectKeyframe(const Keyframe& keyframe, const Pose& T_world_keyframe,
                               const DenseOptions& options = {});

/// All keyframes back-projected, then voxel-filtered (options.voxelSize).
DenseCloud buildDenseCloud(const std::vector<PosedKeyframe>& keyframes,
                           const DenseOptions& options = {});
DenseCloud buildDenseCloud(const KeyframeGraph& graph, const DenseOptions& options = {});

/// The keyframes' feature points (sparse), for maps that kept no images: coloured from the
/// keyframe's colour image when it has one, else by height (world y, blue high to orange low).
DenseCloud buildFeatureCloud(const KeyframeGraph& graph);

/// One point per occupied voxel: the centroid of its points with their mean colour. Uses PCL's
/// VoxelGrid when built with dense outputs, the same algorithm without PCL otherwise.
DenseCloud voxelFilter(const DenseCloud& cloud, double voxelSize);

/// True when built with PCL and OctoMap (CMake option SLAMDUNK_WITH_DENSE): the file writers
/// below and OccupancyMap work; otherwise they throw std::runtime_error saying so.
bool haveDenseFileOutputs();

/// Coloured PLY (binary little-endian unless ascii) and PCD (binary unless ascii), written
/// atomically: an existing file is replaced only on success. Throw std::runtime_error.
void writePly(const DenseCloud& cloud, const std::string& path, bool ascii = false);
void writePcd(const DenseCloud& cloud, const std::string& path, bool ascii = false);
/// Reads a .ply or .pcd file (by extension) with PCL; throws std::runtime_error naming it.
DenseCloud readPointCloud(const std::string& path);

}  // namespace slamdunk
