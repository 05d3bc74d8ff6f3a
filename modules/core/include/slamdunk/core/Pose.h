#pragma once
// SE(3) helpers. The pipeline works with Eigen::Isometry3d poses of the *optical* frame
// (x right, y down, z forward), as TUM trajectories do; MRPT's 3D range sensor frame is
// x forward, y left, z up. These functions convert between the two worlds.

#include <Eigen/Geometry>

namespace mrpt::poses {
class CPose3D;
}

namespace slamdunk {

using Pose = Eigen::Isometry3d;

/// One degree in radians.
inline constexpr double kDeg = 3.14159265358979323846 / 180;

/// Pose from translation and a quaternion (x, y, z, w order as in TUM files); normalises the
/// quaternion and throws std::invalid_argument on NaN/inf values or a zero-norm quaternion.
Pose poseFromTranslationQuaternion(double tx, double ty, double tz, double qx, double qy, double qz,
                                   double qw);

/// The pose turned by `angle` radians about `axis` (of any length) and moved by `t`.
Pose poseFromAxisAngle(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& t);

mrpt::poses::CPose3D toCPose3D(const Pose& p);
Pose fromCPose3D(const mrpt::poses::CPose3D& p);

/// Pose of the optical frame expressed in MRPT's sensor frame: CPose3D(0,0,0,-90°,0,-90°).
const Pose& opticalInSensor();
/// T_w_sensor for a given T_w_optical (and back).
Pose opticalToSensorPose(const Pose& T_w_optical);
Pose sensorToOpticalPose(const Pose& T_w_sensor);

/// Rotation angle of a pose in radians, in [0, pi].
double rotationAngle(const Pose& p);
/// Rotation angle of the rotation between two poses' orientations (radians).
double rotationDistance(const Pose& a, const Pose& b);
double translationDistance(const Pose& a, const Pose& b);

/// The matrix [v]x with [v]x w = v x w (the derivative of a small rotation applied to w).
inline Eigen::Matrix3d skewSymmetric(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// The pose with its rotation part projected back onto SO(3) (undoes rounding in products).
Pose orthonormalized(const Pose& p);

/// True when all entries are finite and the rotation part is orthonormal to 1e-6.
bool isValidPose(const Pose& p);

}  // namespace slamdunk
