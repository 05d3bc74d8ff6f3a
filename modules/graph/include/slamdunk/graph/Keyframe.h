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
  /// Depth (CV_32F metres) subsampled by `depthSmallStride` for dense alignment; always kept,
  /// it costs 77 KB for a VGA frame at stride 4. May be empty (the alignment is then skipped).
  cv::Mat depthSmall;
  int depthSmallStride = 4;
};
using KeyframePtr = std::shared_ptr<const Keyframe>;

}  // namespace slamdunk
