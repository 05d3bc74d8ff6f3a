#pragma once
// The synthetic scenes of the optimization tests: keyframes walking sideways past a wall of
// points, with the wobble of a hand-held camera.

#include <slamdunk/core/Pose.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace slamdunk::test {

/// `count` points uniform in the box from `lo` to `hi`.
inline std::vector<Eigen::Vector3d> pointsInBox(int count, const Eigen::Vector3d& lo,
                                                const Eigen::Vector3d& hi, std::mt19937& rng) {
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), uz(lo.z(), hi.z());
  std::vector<Eigen::Vector3d> points;
  for (int n = 0; n < count; ++n) points.emplace_back(ux(rng), uy(rng), uz(rng));
  return points;
}

/// A camera at `position`, turned by `yaw` about y, then `pitch` about x, then `roll` about z
/// (radians).
inline Pose wobblingPose(const Eigen::Vector3d& position, double yaw, double pitch,
                         double roll = 0) {
  Pose p = Pose::Identity();
  p.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  p.translation() = position;
  return p;
}

}  // namespace slamdunk::test
