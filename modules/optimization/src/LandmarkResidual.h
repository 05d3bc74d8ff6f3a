#pragma once
// One keyframe's observation of a landmark, as a calibrated RGB-D camera measures it: where the
// point appears in the image (pixels, precise to about a keypoint's localisation) and how far
// away it is (the depth read there, whose noise grows with z²). Whitened by those two
// precisions, so that the bundle adjustment trusts each measurement as much as it deserves:
// unlike a 3D-3D difference, a depth error cannot pass for a lateral one.

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace slamdunk {

class LandmarkResidual {
 public:
  /// observed: the point in the keyframe's frame (z > 0); fx, fy: the keyframe's focal lengths
  /// in pixels; pixelSigma in pixels, depthSigma in metres.
  LandmarkResidual(const Eigen::Vector3d& observed, double fx, double fy, double pixelSigma,
                   double depthSigma)
      : u_(observed.x() / observed.z()),
        v_(observed.y() / observed.z()),
        z_(observed.z()),
        scaleU_(fx / pixelSigma),
        scaleV_(fy / pixelSigma),
        scaleZ_(1.0 / depthSigma) {}

  /// q (Eigen x,y,z,w), t: world <- keyframe; landmark: world point.
  template <typename T>
  bool operator()(const T* q, const T* t, const T* landmark, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t), world(landmark);
    const Eigen::Matrix<T, 3, 1> p = rotation.conjugate() * (world - translation);
    if (!(p.z() > T(1e-3))) return false;  // behind the camera: Ceres rejects the step
    residual[0] = T(scaleU_) * (p.x() / p.z() - T(u_));
    residual[1] = T(scaleV_) * (p.y() / p.z() - T(v_));
    residual[2] = T(scaleZ_) * (p.z() - T(z_));
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Vector3d& observed, double fx, double fy,
                                     double pixelSigma, double depthSigma) {
    return new ceres::AutoDiffCostFunction<LandmarkResidual, 3, 4, 3, 3>(
        new LandmarkResidual(observed, fx, fy, pixelSigma, depthSigma));
  }

 private:
  double u_, v_, z_;  ///< normalised image coordinates and depth of the observation
  double scaleU_, scaleV_, scaleZ_;
};

}  // namespace slamdunk
