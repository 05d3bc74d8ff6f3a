#include <slamdunk/core/Pose.h>

#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <stdexcept>

namespace slamdunk {

Pose poseFromTranslationQuaternion(double tx, double ty, double tz, double qx, double qy, double qz,
                                   double qw) {
  for (double v : {tx, ty, tz, qx, qy, qz, qw})
    if (!std::isfinite(v)) throw std::invalid_argument("pose has a NaN or infinite value");
  Eigen::Quaterniond q(qw, qx, qy, qz);
  const double n = q.norm();
  if (n < 1e-9) throw std::invalid_argument("pose has a zero-length quaternion");
  q.coeffs() /= n;
  Pose p = Pose::Identity();
  p.linear() = q.toRotationMatrix();
  p.translation() = Eigen::Vector3d(tx, ty, tz);
  return p;
}

Pose poseFromAxisAngle(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(angle, axis.normalized()).matrix();
  p.translation() = t;
  return p;
}

mrpt::poses::CPose3D toCPose3D(const Pose& p) {
  mrpt::math::CMatrixDouble33 R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = p.linear()(r, c);
  const Eigen::Vector3d t = p.translation();
  return mrpt::poses::CPose3D(R, mrpt::math::CVectorFixedDouble<3>({t.x(), t.y(), t.z()}));
}

Pose fromCPose3D(const mrpt::poses::CPose3D& p) {
  Pose out = Pose::Identity();
  const auto R = p.getRotationMatrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.linear()(r, c) = R(r, c);
  out.translation() = Eigen::Vector3d(p.x(), p.y(), p.z());
  return out;
}

const Pose& opticalInSensor() {
  // MRPT's sensor frame is x forward, y left, z up; the optical frame x right, y down, z forward.
  static const Pose T =
      fromCPose3D(mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0)));
  return T;
}

Pose opticalToSensorPose(const Pose& T_w_optical) {
  return T_w_optical * opticalInSensor().inverse();
}

Pose sensorToOpticalPose(const Pose& T_w_sensor) { return T_w_sensor * opticalInSensor(); }

double rotationAngle(const Pose& p) {
  const double c = std::clamp((p.linear().trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

double rotationDistance(const Pose& a, const Pose& b) { return rotationAngle(a.inverse() * b); }

double translationDistance(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm();
}

Pose orthonormalized(const Pose& p) {
  Pose out = Pose::Identity();
  out.linear() = Eigen::Quaterniond(p.linear()).normalized().toRotationMatrix();
  out.translation() = p.translation();
  return out;
}

bool isValidPose(const Pose& p) {
  if (!p.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = p.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
         R.determinant() > 0;
}

}  // namespace slamdunk
