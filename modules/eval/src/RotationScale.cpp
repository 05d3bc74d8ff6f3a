#include <slamdunk/eval/RotationScale.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace slamdunk::eval {

namespace {
Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd turn(R);
  return turn.angle() * turn.axis();
}
}  // namespace

void RotationScale::add(const Eigen::Matrix3d& reference, const Eigen::Matrix3d& compared) {
  const Eigen::Vector3d r = rotationVector(reference), c = rotationVector(compared);
  referenceTimesCompared_ += r.cwiseProduct(c);
  referenceSquared_ += r.cwiseAbs2();
  comparedSquared_ += c.cwiseAbs2();
  ++count_;
}

Eigen::Vector3d RotationScale::scale() const {
  Eigen::Vector3d s = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const double minSquared =
      std::pow(kMinRotationDegrees * M_PI / 180.0, 2) * static_cast<double>(count_);
  for (int axis = 0; axis < 3; ++axis)
    if (count_ > 0 && referenceSquared_[axis] >= minSquared)
      s[axis] = referenceTimesCompared_[axis] / referenceSquared_[axis];
  return s;
}

Eigen::Vector3d RotationScale::standardError() const {
  const Eigen::Vector3d s = scale();
  Eigen::Vector3d e = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (count_ < 3) return e;
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(s[axis])) continue;
    // Sum of (c - s r)² from the sums, clamped at 0 against rounding.
    const double scatter =
        std::max(0.0, comparedSquared_[axis] - 2 * s[axis] * referenceTimesCompared_[axis] +
                          s[axis] * s[axis] * referenceSquared_[axis]);
    e[axis] = std::sqrt(scatter / static_cast<double>(count_ - 1) / referenceSquared_[axis]);
  }
  return e;
}

Eigen::Vector3d RotationScale::referenceRmsDegrees() const {
  if (count_ == 0) return Eigen::Vector3d::Zero();
  return (referenceSquared_ / static_cast<double>(count_)).cwiseSqrt() * (180.0 / M_PI);
}

}  // namespace slamdunk::eval
