#include <slamdunk/dense/DenseOutputs.h>

#include <chrono>
#include <stdexcept>

namespace slamdunk {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

DenseOutputSummary writeDenseOutputs(const KeyframeGraph& graph, const std::string& prefix,
                                     const DenseOutputOptions& options) {
  if (!haveDenseFileOutputs())
    throw std::runtime_error("dense outputs '" + prefix +
                             ".*': this build has no dense outputs (SLAMDUNK_WITH_DENSE=OFF)");
  options.cloud.validate();
  options.occupancy.validate();
  DenseOutputSummary summary;
  // One snapshot for both outputs, so the cloud and the grid agree even if poses still move.
  const std::vector<PosedKeyframe> keyframes = keyframesWithImages(graph);
  summary.keyframesWithImages = keyframes.size();
  if (keyframes.empty())
    throw std::runtime_error("dense outputs '" + prefix +
                             ".*': no keyframe kept its images (set tracker.keepKeyframeImages)");

  if (options.writeCloud) {
    const auto t0 = std::chrono::steady_clock::now();
    const DenseCloud cloud = buildDenseCloud(keyframes, options.cloud);
    summary.cloudPoints = cloud.size();
    writePly(cloud, prefix + ".ply");
    summary.files.push_back(prefix + ".ply");
    writePcd(cloud, prefix + ".pcd");
    summary.files.push_back(prefix + ".pcd");
    summary.cloudSeconds = secondsSince(t0);
  }
  if (options.writeOccupancy) {
    const auto t0 = std::chrono::steady_clock::now();
    OccupancyMap map(options.occupancy);
    map.insertKeyframes(keyframes);
    summary.occupancy = map.statistics();
    map.writeColourTree(prefix + ".ot");
    summary.files.push_back(prefix + ".ot");
    map.writeBinary(prefix + ".bt");
    summary.files.push_back(prefix + ".bt");
    summary.occupancySeconds = secondsSince(t0);
  }
  return summary;
}

}  // namespace slamdunk
