#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/RgbdFrame.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace slamdunk {

cv::Mat registerDepthToColour(const cv::Mat& depth, const CameraIntrinsics& depthCamera,
                              const CameraIntrinsics& colourCamera,
                              const Eigen::Isometry3d& depthToColourMetres, double metresPerUnit) {
  if (!(metresPerUnit > 0))
    throw std::invalid_argument("registerDepthToColour: metresPerUnit <= 0");
  Eigen::Isometry3d depthToColour = depthToColourMetres;  // in the depth image's units
  depthToColour.translation() /= metresPerUnit;
  if (depth.type() != CV_16UC1 && depth.type() != CV_32FC1)
    throw std::invalid_argument("registerDepthToColour: depth must be CV_16UC1 or CV_32FC1");
  cv::Mat depthF;
  depth.convertTo(depthF, CV_32F);

  // A depth pixel covers about this many colour pixels (per axis) at equal depth: a colour
  // camera with the longer focal length would otherwise see holes between the projections.
  // At most 16: beyond that the depth image is far too coarse to register anyway, and a
  // corrupt focal length must neither overflow the cast nor make this loop quadratic.
  const double ratio = std::max(colourCamera.fx / depthCamera.fx, colourCamera.fy / depthCamera.fy);
  const int footprint =
      std::isfinite(ratio) ? static_cast<int>(std::clamp(std::ceil(ratio - 1e-9), 1.0, 16.0)) : 1;
  // Most RGB-D cameras state no lens distortion: then the lens model is skipped per pixel.
  const bool depthLens = depthCamera.hasDistortion(), colourLens = colourCamera.hasDistortion();
  cv::Mat out(colourCamera.height, colourCamera.width, CV_32F, cv::Scalar(0));
  for (int r = 0; r < depthF.rows; ++r) {
    const float* row = depthF.ptr<float>(r);
    for (int c = 0; c < depthF.cols; ++c) {
      const float z = row[c];
      if (!(z > 0) || !std::isfinite(z)) continue;
      const Eigen::Vector2d und =
          depthLens ? depthCamera.undistortPixel(c, r) : Eigen::Vector2d(c, r);
      const Eigen::Vector3d p = depthToColour * depthCamera.backProject(und.x(), und.y(), z);
      if (!(p.z() > 0)) continue;
      const Eigen::Vector2d px = colourCamera.project(p);
      const Eigen::Vector2d raw = colourLens ? colourCamera.distortPixel(px.x(), px.y()) : px;
      // Far outside the image (or NaN from a degenerate calibration): nothing to write, and
      // the int conversion below would overflow.
      if (!(std::abs(raw.x()) < 1e8 && std::abs(raw.y()) < 1e8)) continue;
      // The footprint's pixels around the projection (one pixel when footprint is 1).
      const int u0 = static_cast<int>(std::lround(raw.x() - 0.5 * (footprint - 1)));
      const int v0 = static_cast<int>(std::lround(raw.y() - 0.5 * (footprint - 1)));
      const float zc = static_cast<float>(p.z());
      for (int v = std::max(v0, 0); v < std::min(v0 + footprint, out.rows); ++v) {
        float* outRow = out.ptr<float>(v);
        for (int u = std::max(u0, 0); u < std::min(u0 + footprint, out.cols); ++u)
          if (outRow[u] == 0 || zc < outRow[u]) outRow[u] = zc;
      }
    }
  }

  // The splat above gives a colour pixel the depth of the depth pixel whose projection is
  // nearest, up to half a pixel away: on a slanted surface an error fixed to the image, which
  // a map keeps from every viewpoint. Where the colour ray's landing point in the depth image
  // lies on one surface, the depth is read there instead (the splat's depth only places the
  // ray's point: with the cameras' centres apart, where it lands depends on it, little).
  const Eigen::Isometry3d colourToDepth = depthToColour.inverse();
  for (int v = 0; v < out.rows; ++v) {
    float* outRow = out.ptr<float>(v);
    for (int u = 0; u < out.cols; ++u) {
      if (outRow[u] == 0) continue;
      const Eigen::Vector2d und =
          colourLens ? colourCamera.undistortPixel(u, v) : Eigen::Vector2d(u, v);
      const Eigen::Vector3d inDepth =
          colourToDepth * colourCamera.backProject(und.x(), und.y(), outRow[u]);
      if (!(inDepth.z() > 0)) continue;
      const Eigen::Vector2d px = depthCamera.project(inDepth);
      const Eigen::Vector2d raw = depthLens ? depthCamera.distortPixel(px.x(), px.y()) : px;
      const double z = depthOnOneSurface(depthF, raw.x(), raw.y());
      if (!(z > 0)) continue;
      const Eigen::Vector3d onSurface = inDepth * (z / inDepth.z());
      outRow[u] = static_cast<float>((depthToColour * onSurface).z());
    }
  }
  if (depth.type() == CV_32FC1) return out;
  cv::Mat out16;
  out.convertTo(out16, CV_16U);  // rounds to the nearest raw unit
  return out16;
}

}  // namespace slamdunk
