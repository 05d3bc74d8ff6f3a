#pragma once
// Closed-form least-squares rigid alignment of two corresponding 3D point sets (Horn 1987 /
// Umeyama 1991 / Kabsch, without scale), as evaluate_ate.py's align() computes it.

#include <Eigen/Geometry>

#include <vector>

namespace slamdunk::eval {

struct RigidAlignment {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  /// The alignment as a transform: target ~ transform() * source.
  Eigen::Isometry3d transform() const;
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return rotation * p + translation; }

  /// The proper rotation R (det +1, never a reflection) and translation t minimising
  /// sum_i |R * source[i] + t - target[i]|^2. Throws std::invalid_argument when the sizes differ
  /// or there are fewer than 3 points. Degenerate (collinear) sets give one of the optimal
  /// rotations.
  static RigidAlignment compute(const std::vector<Eigen::Vector3d>& source,
                                const std::vector<Eigen::Vector3d>& target);
};

}  // namespace slamdunk::eval
