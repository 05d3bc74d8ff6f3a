#pragma once
// A keyframe: a tracked frame kept in the map, with its features and (optionally) its images.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/features/FeatureSet.h>

#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>

namespace slamdunk {

using KeyframeId = uint32_t;

struct Keyframe {
  KeyframeId id = 0;
  double timestamp = 0;
  /// Features with 3D points in this keyframe's optical frame. Immutable once in the graph.
  FeatureSet features;
  CameraIntrinsics intrinsics;
  /// Kept only when dense outputs are wanted (colour BGR and depth in metres); may be empty.
  cv::Mat colour;
  cv::Mat depth;
  /// Depth in metres subsampled by `depthSmallStride` for dense alignment, always kept: half
  /// floats (CV_16F, 38 KB for a VGA frame at stride 4; at most 1 mm coarser at 2 m, 2 mm at
  /// 4 m, well below a Kinect's noise), or CV_32F in maps saved before. May be empty (the
  /// alignment is then skipped).
  cv::Mat depthSmall;
  int depthSmallStride = 4;
};
using KeyframePtr = std::shared_ptr<const Keyframe>;

}  // namespace slamdunk
