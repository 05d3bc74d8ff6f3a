#pragma once
// One call for an application: every dense output of a finished (or running) SLAM map.

#include <slamdunk/dense/DenseReconstruction.h>
#include <slamdunk/dense/OccupancyMap.h>

#include <string>
#include <vector>

namespace slamdunk {

struct DenseOutputOptions {
  DenseOptions cloud;
  OccupancyMapOptions occupancy;
  bool writeCloud = true;      ///< PREFIX.ply and PREFIX.pcd
  bool writeOccupancy = true;  ///< PREFIX.ot and PREFIX.bt
};

struct DenseOutputSummary {
  size_t keyframesWithImages = 0;
  size_t cloudPoints = 0;  ///< after the voxel filter
  OccupancyStatistics occupancy;
  std::vector<std::string> files;  ///< written, in order
  double cloudSeconds = 0, occupancySeconds = 0;
};

/// Writes PREFIX.ply, PREFIX.pcd (the voxel-filtered cloud) and PREFIX.ot, PREFIX.bt (the
/// occupancy grid) from the graph's keyframes that kept their images (SlamOptions:
/// tracker.keepKeyframeImages = true). Throws std::runtime_error when no keyframe has images,
/// when built without dense outputs, or when a file cannot be written.
DenseOutputSummary writeDenseOutputs(const KeyframeGraph& graph, const std::string& prefix,
                                     const DenseOutputOptions& options = {});

}  // namespace slamdunk
