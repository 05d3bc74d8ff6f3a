#include <slamdunk/core/CameraIntrinsics.h>

#include <mrpt/img/TCamera.h>

#include <cmath>

namespace slamdunk {

bool CameraIntrinsics::hasDistortion() const {
  for (double d : dist)
    if (d != 0.0) return true;
  return false;
}

std::string CameraIntrinsics::problem() const {
  if (width <= 0 || height <= 0)
    return "resolution " + std::to_string(width) + "x" + std::to_string(height) +
           " is not positive";
  for (double v : {fx, fy, cx, cy})
    if (!std::isfinite(v)) return "fx, fy, cx and cy must be finite numbers";
  if (!(fx >= 1e-3 && fx <= 1e6 && fy >= 1e-3 && fy <= 1e6))
    return "focal lengths fx = " + std::to_string(fx) + ", fy = " + std::to_string(fy) +
           " must be in [0.001, 1e6] pixels";
  if (std::abs(cx) > 1e6 || std::abs(cy) > 1e6)
    return "principal point (" + std::to_string(cx) + ", " + std::to_string(cy) +
           ") is more than 1e6 pixels away";
  for (double d : dist)
    if (!(std::abs(d) <= 1000.0)) return "distortion coefficients must be finite, within +-1000";
  return {};
}

Eigen::Vector2d CameraIntrinsics::undistortPixel(double u, double v) const {
  if (!hasDistortion()) return {u, v};
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double xd = (u - cx) / fx, yd = (v - cy) / fy;
  // Fixed-point inversion of the forward model, as cv::undistortPoints does; a handful of
  // iterations converge to far below a hundredth of a pixel for Kinect-like lenses.
  double x = xd, y = yd;
  for (int it = 0; it < 10; ++it) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    const double dy = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
    x = (xd - dx) / radial;
    y = (yd - dy) / radial;
  }
  return {x * fx + cx, y * fy + cy};
}

Eigen::Vector2d CameraIntrinsics::distortPixel(double u, double v) const {
  if (!hasDistortion()) return {u, v};
  const double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
  const double x = (u - cx) / fx, y = (v - cy) / fy;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {xd * fx + cx, yd * fy + cy};
}

CameraIntrinsics CameraIntrinsics::fromTCamera(const mrpt::img::TCamera& cam) {
  CameraIntrinsics c;
  c.width = static_cast<int>(cam.ncols);
  c.height = static_cast<int>(cam.nrows);
  c.fx = cam.fx();
  c.fy = cam.fy();
  c.cx = cam.cx();
  c.cy = cam.cy();
  for (size_t i = 0; i < 5; ++i) c.dist[i] = cam.dist[i];
  return c;
}

mrpt::img::TCamera CameraIntrinsics::toTCamera() const {
  mrpt::img::TCamera cam;
  cam.ncols = static_cast<uint32_t>(width);
  cam.nrows = static_cast<uint32_t>(height);
  cam.setIntrinsicParamsFromValues(fx, fy, cx, cy);
  for (size_t i = 0; i < 5; ++i) cam.dist[i] = dist[i];
  return cam;
}

}  // namespace slamdunk
