#pragma once
// A depth image back-projected into 3D points (paper Eq. 2), with the colour of each point's
// pixel: the one walk over a keyframe's depth behind every view of the map (the map plug-in's
// cloud, the dense cloud and the live viewer's cloud).

#include <slamdunk/core/CameraIntrinsics.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>

namespace slamdunk {

/// Which pixels of a depth image become points.
struct DepthSampling {
  int step = 1;  ///< every step-th depth pixel in rows and columns
  /// Full-image pixels per depth pixel: the stride of a subsampled depth image, whose points
  /// are projected through the full image's intrinsics.
  int pixelScale = 1;
  bool undistort = false;  ///< remove the lens distortion of the intrinsics first
};

/// Calls fn(u, v, p) for every sampled pixel of a CV_32F depth image (metres) whose depth z
/// keepDepth(z) accepts, row by row: (u, v) is the pixel in the full image, p its 3D point in
/// the camera's optical frame. Which depths are readings is the caller's to say: views differ
/// in the range they trust.
template <class KeepDepth, class Fn>
void forEachDepthPoint(const cv::Mat& depth, const CameraIntrinsics& K,
                       const DepthSampling& sampling, KeepDepth&& keepDepth, Fn&& fn) {
  if (depth.empty()) return;
  if (depth.type() != CV_32FC1) throw std::invalid_argument("depth image must be CV_32F metres");
  const int step = std::max(1, sampling.step), scale = std::max(1, sampling.pixelScale);
  const bool undistort = sampling.undistort && K.hasDistortion();
  for (int r = 0; r < depth.rows; r += step) {
    const float* row = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; c += step) {
      const float z = row[c];
      if (!keepDepth(z)) continue;
      const int u = c * scale, v = r * scale;
      const Eigen::Vector2d px =
          undistort ? K.undistortPixel(u, v) : Eigen::Vector2d(double(u), double(v));
      fn(u, v, K.backProject(px.x(), px.y(), z));
    }
  }
}

/// Red, green and blue of pixel (u, v) of a BGR (CV_8UC3) or grey (CV_8UC1) image, the kinds
/// keyframes keep; nothing for another kind of image or a pixel outside it.
std::optional<std::array<uint8_t, 3>> rgbAt(const cv::Mat& image, int u, int v);

}  // namespace slamdunk
