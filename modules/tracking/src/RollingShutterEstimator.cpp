#include <slamdunk/core/Pose.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace slamdunk {

RollingShutterEstimator::RollingShutterEstimator(double initialMs,
                                                 const RollingShutterEstimatorOptions& options)
    : options_(options), current_(initialMs) {}

double RollingShutterEstimator::sigmaMs() const {
  return information_ > 0 ? 1.0 / std::sqrt(information_) : std::numeric_limits<double>::infinity();
}

void RollingShutterEstimator::addFrame(const std::vector<InlierSample>& inliers, const Pose& pose,
                                       const Pose& motion, double intervalMs,
                                       const DepthNoiseModel& noise, double appliedMs) {
  if (!options_.enabled || !(intervalMs > 0) || inliers.size() < 10) return;
  // The motion per millisecond, as a twist: a row exposed τ ms after the frame's time sees the
  // scene from a camera moved by τ·(ω, v), so its point p reads as p + τ (ω × p + v) in the
  // frame's camera.
  const Eigen::AngleAxisd rotation(motion.linear());
  const Eigen::Vector3d omega = rotation.angle() * rotation.axis() / intervalMs;
  const Eigen::Vector3d velocity = motion.translation() / intervalMs;
  const Pose frameFromWorld = pose.inverse();

  // Normal equations of (pose increment δ, readout increment) over the inliers: the residual
  // r = T⁻¹P − q(readout) with q the corrected frame point; T ← T exp(δ) moves T⁻¹P by
  // [x]× φ − u, and the readout moves q by rowFraction (ω × q + v) per millisecond.
  Eigen::Matrix<double, 7, 7> H = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 1> g = Eigen::Matrix<double, 7, 1>::Zero();
  for (const InlierSample& s : inliers) {
    const Eigen::Vector3d x = frameFromWorld * s.mapPoint;
    const Eigen::Vector3d r = x - s.framePoint;
    // Both points' noise, the map point's taken as if seen from here (its keyframe saw it
    // from nearby).
    const Eigen::Matrix3d W = (2 * noise.covariance(s.framePoint)).inverse();
    const double d = std::sqrt(std::max(0.0, r.dot(W * r)));
    const double robust = d <= options_.huberSigmas ? 1.0 : options_.huberSigmas / d;
    Eigen::Matrix<double, 3, 7> J;
    J.block<3, 3>(0, 0) = skewSymmetric(x);
    J.block<3, 3>(0, 3) = -Eigen::Matrix3d::Identity();
    J.col(6) = -s.rowFraction * (omega.cross(s.framePoint) + velocity);
    H += robust * J.transpose() * W * J;
    g += robust * J.transpose() * W * r;
  }
  // Marginalise the pose: what the frame says of the readout with its pose free.
  const Eigen::Matrix<double, 6, 6> Hpp = H.topLeftCorner<6, 6>();
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(Hpp);
  if (solver.info() != Eigen::Success) return;
  const Eigen::Matrix<double, 6, 1> Hpr = H.block<6, 1>(0, 6);
  const double information = H(6, 6) - Hpr.dot(solver.solve(Hpr));
  const double gradient = g(6) - Hpr.dot(solver.solve(g.head<6>()));
  if (!(information > 1e-12) || !std::isfinite(gradient)) return;
  const double said =
      std::clamp(appliedMs - gradient / information, -options_.maxMs, 2 * options_.maxMs);

  window_.push_back({said, information});
  if (static_cast<int>(window_.size()) > options_.window) window_.pop_front();
  double sum = 0;
  information_ = 0;
  for (const Evidence& e : window_) {
    sum += e.information * e.readoutMs;
    information_ += e.information;
  }
  if (sigmaMs() <= options_.maxSigmaMs) {
    current_ = std::clamp(sum / information_, 0.0, options_.maxMs);
    learned_ = true;
  }
}

}  // namespace slamdunk
