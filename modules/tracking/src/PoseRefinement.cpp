#include <slamdunk/tracking/PoseRefinement.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>

namespace slamdunk {

namespace {
Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}
}  // namespace

Pose refinePose(const Pose& initial, const std::vector<PosePair>& pairs,
                const PoseRefinementOptions& options) {
  Pose T = initial;
  if (pairs.size() < 3) return T;
  for (int it = 0; it < options.iterations; ++it) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    const Eigen::Matrix3d R = T.linear();
    for (const PosePair& p : pairs) {
      const Eigen::Vector3d q = T * p.source;
      const Eigen::Vector3d e = q - p.target;
      const Eigen::Matrix3d cov = R * p.sourceCov * R.transpose() + p.targetCov;
      const Eigen::Matrix3d info = cov.inverse();
      const double m2 = e.dot(info * e);  // squared Mahalanobis distance
      const double m = std::sqrt(m2);
      const double w = m <= options.huberSigmas ? 1.0 : options.huberSigmas / m;
      // Left perturbation: exp(δ) T p ≈ q + δt + δω × q, so de/dδ = [I, -[q]×].
      Eigen::Matrix<double, 3, 6> J;
      J.leftCols<3>() = Eigen::Matrix3d::Identity();
      J.rightCols<3>() = -skew(q);
      H += w * J.transpose() * info * J;
      g += w * J.transpose() * info * e;
    }
    const Eigen::Matrix<double, 6, 1> delta = -H.ldlt().solve(g);
    if (!delta.allFinite()) break;
    Pose step = Pose::Identity();
    const double angle = delta.tail<3>().norm();
    if (angle > 1e-12)
      step.linear() = Eigen::AngleAxisd(angle, delta.tail<3>() / angle).toRotationMatrix();
    step.translation() = delta.head<3>();
    T = step * T;
    if (delta.norm() < 1e-9) break;
  }
  return T;
}

}  // namespace slamdunk
