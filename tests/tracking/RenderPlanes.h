#pragma once
// Exact depth images of scenes made of planes, by ray casting: ground truth for the dense
// alignment tests.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>

#include <opencv2/core.hpp>

#include <vector>

namespace slamdunk::test {

/// The plane n·x + offset = 0 (world frame).
struct Plane {
  Eigen::Vector3d normal;
  double offset;
};

/// A corner 2.5 m ahead: floor (y = 0.8, y points down), a wall at x = 0.9, a wall at z = 2.5.
inline std::vector<Plane> cornerPlanes() {
  return {{{0, -1, 0}, 0.8}, {{-1, 0, 0}, 0.9}, {{0, 0, -1}, 2.5}};
}

/// Distance along the ray `dirCam` (camera frame, z = 1, so the distance is the depth) to the
/// nearest plane, for a camera at `pose` (world <- camera); 0 where no plane is hit.
inline double depthAlongRay(const Pose& pose, const Eigen::Vector3d& dirCam,
                            const std::vector<Plane>& planes) {
  const Eigen::Vector3d o = pose.translation(), d = pose.linear() * dirCam;
  double best = 0;
  for (const Plane& p : planes) {
    const double denom = p.normal.dot(d);
    if (std::abs(denom) < 1e-9) continue;
    const double t = -(p.normal.dot(o) + p.offset) / denom;
    if (t > 0 && (best == 0 || t < best)) best = t;
  }
  return best;
}

/// Depth (CV_32F metres) of the nearest plane along each pixel's ray, for a camera at `pose`
/// (world <- camera); 0 where no plane is hit.
inline cv::Mat renderPlanes(const CameraIntrinsics& K, const Pose& pose,
                            const std::vector<Plane>& planes) {
  cv::Mat depth(K.height, K.width, CV_32F, cv::Scalar(0));
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d dirCam((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      depth.at<float>(v, u) = static_cast<float>(depthAlongRay(pose, dirCam, planes));
    }
  return depth;
}

/// A pinhole camera with its principal point at the image centre.
inline CameraIntrinsics centredCamera(int width, int height, double focal) {
  CameraIntrinsics K;
  K.width = width;
  K.height = height;
  K.fx = K.fy = focal;
  K.cx = (width - 1) / 2.0;
  K.cy = (height - 1) / 2.0;
  return K;
}

/// A small camera (160x120) for these images.
inline CameraIntrinsics smallCamera() { return centredCamera(160, 120, 130); }

}  // namespace slamdunk::test
