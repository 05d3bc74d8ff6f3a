#pragma once
// Noise of a 3D point back-projected from an RGB-D pixel: small across the viewing ray (about a
// pixel of keypoint error), large along it (structured-light depth error grows with z²,
// Khoshelham & Elberink 2012). Shared by the pose refinement and the graph edge weights.

#include <Eigen/Core>

namespace slamdunk {

struct DepthNoiseModel {
  double pixelSigma = 1.0;              ///< keypoint localisation, pixels
  double focalLength = 525.0;           ///< pixels
  double depthSigmaQuadratic = 0.0015;  ///< σ_z = a z² (+ the lateral term)

  double lateralSigma(double z) const { return pixelSigma * z / focalLength; }
  double depthSigma(double z) const { return depthSigmaQuadratic * z * z + lateralSigma(z); }
  /// Covariance of a point p (in its camera's frame): anisotropic around the ray through p.
  Eigen::Matrix3d covariance(const Eigen::Vector3d& p) const {
    const double z = p.z();
    const double lat2 = lateralSigma(z) * lateralSigma(z), dep2 = depthSigma(z) * depthSigma(z);
    const Eigen::Vector3d ray = p.normalized();
    return lat2 * Eigen::Matrix3d::Identity() + (dep2 - lat2) * ray * ray.transpose();
  }
  /// Variance across the ray added for a keypoint detected at `size` pixels whose position is
  /// uncertain by `fraction` of that size: coarse-scale keypoints are localised coarsely.
  double keypointScaleVariance(double z, double size, double fraction) const {
    const double s = fraction * size * z / focalLength;
    return s * s;
  }
  /// Isotropic variance of the same point (trace / 3), for scalar weights.
  double variance(double z) const {
    const double l = lateralSigma(z), d = depthSigma(z);
    return (2 * l * l + d * d) / 3 + 1e-10;
  }
};

}  // namespace slamdunk
