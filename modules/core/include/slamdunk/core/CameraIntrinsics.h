#pragma once
// Pinhole camera with OpenCV-order distortion (k1 k2 p1 p2 k3), the colour camera of an RGB-D
// sensor.

#include <Eigen/Core>
#include <array>
#include <string>

namespace mrpt::img {
class TCamera;
}
namespace mrpt::config {
class CConfigFileBase;
}

namespace slamdunk {

struct CameraIntrinsics {
  int width = 640;
  int height = 480;
  double fx = 525.0, fy = 525.0, cx = 319.5, cy = 239.5;
  /// OpenCV order: k1 k2 p1 p2 k3. All zero = no distortion.
  std::array<double, 5> dist{0, 0, 0, 0, 0};

  bool hasDistortion() const;
  /// Empty when the calibration is usable, else what is wrong with it: a non-positive size,
  /// a non-finite value, or a value no camera has (focal length outside [1e-3, 1e6] px,
  /// principal point farther than 1e6 px, a distortion coefficient beyond +-1000). Data read
  /// from files is checked with this before any pixel is projected.
  std::string problem() const;

  /// Paper Eq. 2: the 3D point (optical frame, metres) of an *undistorted* pixel at depth z.
  Eigen::Vector3d backProject(double u, double v, double z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
  /// Pinhole projection (no distortion) of an optical-frame point; z must be > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  /// Removes lens distortion from a raw pixel (iterative inverse of the OpenCV model).
  Eigen::Vector2d undistortPixel(double u, double v) const;
  /// Adds lens distortion to an undistorted pixel (the OpenCV forward model).
  Eigen::Vector2d distortPixel(double u, double v) const;

  static CameraIntrinsics fromTCamera(const mrpt::img::TCamera& cam);
  mrpt::img::TCamera toTCamera() const;
};

}  // namespace slamdunk
