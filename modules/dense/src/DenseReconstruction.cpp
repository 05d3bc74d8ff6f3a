#include <slamdunk/core/DepthBackProjection.h>
#include <slamdunk/dense/DenseReconstruction.h>
#include <slamdunk/dense/OccupancyMap.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace slamdunk {

namespace {

void requirePositive(double v, const char* name) {
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + " must be > 0, not " + std::to_string(v));
}

void validateDepthRange(int stride, double minDepth, double maxDepth, const char* what) {
  if (stride < 1)
    throw std::invalid_argument(std::string(what) + ": pixel stride must be >= 1, not " +
                                std::to_string(stride));
  if (!(minDepth >= 0) || !(maxDepth > minDepth) || !std::isfinite(maxDepth))
    throw std::invalid_argument(std::string(what) + ": depth range [" + std::to_string(minDepth) +
                                ", " + std::to_string(maxDepth) + "] is empty or invalid");
}

/// The colour of an image pixel; neutral grey without a usable image.
DenseCloud::Rgb colourAt(const cv::Mat& image, int u, int v) {
  return rgbAt(image, u, v).value_or(DenseCloud::Rgb{200, 200, 200});
}

}  // namespace

void DenseOptions::validate() const {
  validateDepthRange(pixelStride, minDepth, maxDepth, "dense cloud");
  if (!(voxelSize >= 0) || !std::isfinite(voxelSize))
    throw std::invalid_argument("dense cloud: voxel size must be >= 0, not " +
                                std::to_string(voxelSize));
}

void OccupancyMapOptions::validate() const {
  validateDepthRange(pixelStride, minDepth, maxDepth, "occupancy map");
  requirePositive(resolution, "occupancy map: resolution");
}

std::vector<PosedKeyframe> keyframesWithImages(const KeyframeGraph& graph) {
  std::vector<PosedKeyframe> out;
  // One consistent snapshot of the poses: the optimizer may be moving them meanwhile.
  for (const auto& [id, pose] : graph.poses()) {
    KeyframePtr kf = graph.keyframe(id);
    if (kf && !kf->depth.empty()) out.push_back({std::move(kf), pose});
  }
  return out;
}

DenseCloud backProjectKeyframe(const Keyframe& keyframe, const Pose& T_world_keyframe,
                               const DenseOptions& options) {
  options.validate();
  DenseCloud cloud;
  const cv::Mat& depth = keyframe.depth;
  if (depth.empty()) return cloud;
  if (depth.type() != CV_32FC1)
    throw std::invalid_argument("keyframe " + std::to_string(keyframe.id) +
                                ": depth must be CV_32F metres");
  const CameraIntrinsics& K = keyframe.intrinsics;
  // The colour image is registered to the depth map; scale coordinates if sizes differ anyway.
  const cv::Mat& colour = keyframe.colour;
  const double sx = colour.empty() ? 1.0 : double(colour.cols) / depth.cols;
  const double sy = colour.empty() ? 1.0 : double(colour.rows) / depth.rows;
  const Eigen::Matrix3f R = T_world_keyframe.linear().cast<float>();
  const Eigen::Vector3f t = T_world_keyframe.translation().cast<float>();

  const int s = options.pixelStride;
  cloud.reserve(size_t(depth.rows / s + 1) * size_t(depth.cols / s + 1));
  forEachDepthPoint(
      depth, K, DepthSampling{s, 1, options.undistort},
      [&](float z) { return std::isfinite(z) && z >= options.minDepth && z <= options.maxDepth; },
      [&](int u, int v, const Eigen::Vector3d& p) {
        const int cu = std::min(colour.cols - 1, int(u * sx));
        const int cv = std::min(colour.rows - 1, int(v * sy));
        const Eigen::Vector3f pf = p.cast<float>();
        cloud.add(R * pf + t, colourAt(colour, cu, cv));
      });
  return cloud;
}

DenseCloud buildDenseCloud(const std::vector<PosedKeyframe>& keyframes,
                           const DenseOptions& options) {
  options.validate();
  DenseCloud all;
  for (const auto& pk : keyframes) {
    if (!pk.keyframe) continue;
    all.append(backProjectKeyframe(*pk.keyframe, pk.pose, options));
  }
  return options.voxelSize > 0 ? voxelFilter(all, options.voxelSize) : all;
}

DenseCloud buildFeatureCloud(const KeyframeGraph& graph) {
  DenseCloud cloud;
  std::vector<bool> hasColour;
  for (const auto& [id, pose] : graph.poses()) {
    const KeyframePtr kf = graph.keyframe(id);
    if (!kf) continue;
    const auto& f = kf->features;
    for (size_t i = 0; i < f.points.size() && i < f.keypoints.size(); ++i) {
      const cv::Point2f& px = f.keypoints[i].pt;
      const int u = int(std::lround(px.x)), v = int(std::lround(px.y));
      const bool inside =
          !kf->colour.empty() && u >= 0 && v >= 0 && u < kf->colour.cols && v < kf->colour.rows;
      cloud.add((pose * f.points[i]).cast<float>(),
                inside ? colourAt(kf->colour, u, v) : DenseCloud::Rgb{0, 0, 0});
      hasColour.push_back(inside);
    }
  }
  Eigen::Vector3f lo, hi;
  if (!cloud.boundingBox(lo, hi, 0.02, 0.98)) return cloud;
  const float span = std::max(1e-3f, hi.y() - lo.y());
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (hasColour[i]) continue;
    const float t = std::clamp((cloud.points[i].y() - lo.y()) / span, 0.0f, 1.0f);  // 0 = high
    cloud.colours[i] = {uint8_t(60 + 195 * t), uint8_t(140 + 30 * t), uint8_t(255 - 215 * t)};
  }
  return cloud;
}

DenseCloud buildDenseCloud(const KeyframeGraph& graph, const DenseOptions& options) {
  return buildDenseCloud(keyframesWithImages(graph), options);
}

}  // namespace slamdunk
