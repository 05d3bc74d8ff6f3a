#pragma once
// How much one set of relative rotations turns for each turn of another, per camera axis (x
// right, y down, z forward): the least-squares factor s with compared ≈ s · reference between
// their rotation vectors. Turns about x and y (tilt, pan) are read through a camera's focal
// length in pixels, turns about z (roll) are not, and random error in `compared` does not bias
// s: a factor that differs between the axes points at intrinsics or at the reference.

#include <Eigen/Core>

#include <cstddef>

namespace slamdunk::eval {

class RotationScale {
 public:
  /// Axes the reference turns about by less than this (rms over the pairs) have no scale.
  static constexpr double kMinRotationDegrees = 1.0;

  /// One pair of relative rotations of the same motion.
  void add(const Eigen::Matrix3d& reference, const Eigen::Matrix3d& compared);
  std::size_t count() const { return count_; }
  /// Per axis; NaN for an axis the reference turns about by less than kMinRotationDegrees rms.
  Eigen::Vector3d scale() const;
  /// Per axis, the standard error of scale() (NaN where it is NaN or with fewer than 3 pairs):
  /// the scatter of `compared` about s · reference over the reference's spread.
  Eigen::Vector3d standardError() const;
  /// Per axis, the reference's rms turn (degrees).
  Eigen::Vector3d referenceRmsDegrees() const;

 private:
  Eigen::Vector3d referenceTimesCompared_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d referenceSquared_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d comparedSquared_ = Eigen::Vector3d::Zero();
  std::size_t count_ = 0;
};

}  // namespace slamdunk::eval
