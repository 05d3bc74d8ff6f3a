#pragma once
// Robust rigid alignment of 3D point pairs: 3-point minimal samples (Horn/Umeyama), seeded and
// deterministic, adaptive iteration count, then a least-squares fit on all inliers.

#include <slamdunk/core/Pose.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace slamdunk {

struct RansacOptions {
  double inlierThreshold = 0.03;    ///< metres, at zero depth
  double depthCoefficient = 0.005;  ///< threshold grows by this × z² (Kinect noise ~ z²)
  double confidence = 0.99;         ///< p: stop when an all-inlier sample was likely drawn
  int maxIterations = 1000;
  int minInliers = 12;
  uint32_t seed = 42;

  /// Its INI keys (in [tracker]), listed once for IniSectionReader and IniSectionWriter.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("ransac_threshold", o.inlierThreshold);
    k("ransac_depth_coefficient", o.depthCoefficient);
    k("ransac_confidence", o.confidence);
    k("ransac_max_iterations", o.maxIterations);
    k("min_inliers", o.minInliers);
    k("ransac_seed", o.seed);
  }
};

struct RansacResult {
  bool success = false;
  Pose transform = Pose::Identity();  ///< maps source points onto target points
  std::vector<bool> inliers;
  size_t inlierCount = 0;
  int iterations = 0;
  double rmse = 0;  ///< of the inliers after the final fit, metres
};

/// Least-squares rigid transform (no scale) mapping src onto dst (Horn/Umeyama, SVD form),
/// optionally weighted. Needs >= 3 non-collinear pairs.
Pose fitRigidTransform(const std::vector<Eigen::Vector3d>& src,
                       const std::vector<Eigen::Vector3d>& dst,
                       const std::vector<double>* weights = nullptr);

/// src[i] ↔ dst[i]; the threshold's depth term uses src[i].z() (the camera's own depth).
/// refitWeights (optional, one per pair) weigh the final least-squares fit on the inliers, e.g.
/// by the inverse variance of the pair's depth noise.
RansacResult ransacAbsoluteOrientation(const std::vector<Eigen::Vector3d>& src,
                                       const std::vector<Eigen::Vector3d>& dst,
                                       const RansacOptions& options,
                                       const std::vector<double>* refitWeights = nullptr);

}  // namespace slamdunk
