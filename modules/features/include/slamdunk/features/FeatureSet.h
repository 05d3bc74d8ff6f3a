#pragma once
// The visual features of one RGB-D frame that have valid depth, with their 3D points.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <vector>

namespace slamdunk {

struct FeatureSet {
  std::vector<cv::KeyPoint> keypoints;  ///< raw (distorted) image coordinates
  /// One row per keypoint: CV_32F, CV_8U for binary ones, or, in keyframes, CV_16F or CV_8S for
  /// float ones kept as half floats or 8-bit codes (CompactDescriptors.h).
  cv::Mat descriptors;
  std::vector<Eigen::Vector3d> points;  ///< optical-frame 3D point of each keypoint, metres

  size_t size() const { return keypoints.size(); }
  bool empty() const { return keypoints.empty(); }
  bool binary() const { return descriptors.type() == CV_8U; }
};

}  // namespace slamdunk
