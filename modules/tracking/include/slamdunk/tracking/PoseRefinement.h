#pragma once
// Refines a camera pose from 3D-3D inlier pairs by minimising the Mahalanobis distance under
// anisotropic depth noise (Gauss-Newton on SE(3), Huber-robust). Beyond the paper: RANSAC's
// isotropic least squares lets the noisy depth of far points pull the pose along their rays.

#include <slamdunk/core/Pose.h>

#include <Eigen/Core>
#include <vector>

namespace slamdunk {

struct PosePair {
  Eigen::Vector3d source;        ///< in the camera being posed
  Eigen::Vector3d target;        ///< in the world
  Eigen::Matrix3d sourceCov;     ///< in the camera's frame
  Eigen::Matrix3d targetCov;     ///< in the world frame
};

struct PoseRefinementOptions {
  int iterations = 6;
  double huberSigmas = 2.5;  ///< residuals beyond this many standard deviations are down-weighted
};

/// Returns the refined T (maps source to target), starting from `initial`.
Pose refinePose(const Pose& initial, const std::vector<PosePair>& pairs,
                const PoseRefinementOptions& options = {});

}  // namespace slamdunk
