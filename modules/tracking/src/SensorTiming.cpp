#include <slamdunk/tracking/SensorTiming.h>

#include <Eigen/Geometry>

namespace slamdunk {

Pose SensorTiming::interpolate(const Pose& motion, double fraction) {
  const Eigen::AngleAxisd rotation(motion.linear());
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(rotation.angle() * fraction, rotation.axis()).toRotationMatrix();
  T.translation() = fraction * motion.translation();
  return T;
}

Twist SensorTiming::twist(const Pose& motion, double ms) {
  const Eigen::AngleAxisd rotation(motion.linear());
  Twist v;
  v.head<3>() = motion.translation() / (ms / 1000.0);
  v.tail<3>() = rotation.angle() * rotation.axis() / (ms / 1000.0);
  return v;
}

Pose SensorTiming::motion(const Twist& velocity, double ms) {
  const double seconds = ms / 1000.0;
  const Eigen::Vector3d angleAxis = velocity.tail<3>() * seconds;
  Pose T = Pose::Identity();
  const double angle = angleAxis.norm();
  if (angle > 1e-12) T.linear() = Eigen::AngleAxisd(angle, angleAxis / angle).toRotationMatrix();
  T.translation() = velocity.head<3>() * seconds;
  return T;
}

Eigen::Matrix<double, 3, 6> SensorTiming::velocityJacobian(const Eigen::Vector3d& point, double row,
                                                           double rows) const {
  // The camera at τ seconds from the frame's time is exp(τ ν): a point seen then is, in the
  // frame's camera, p + τ (v + ω × p).
  const double rowSeconds = rowFraction(row, rows) * options_.rollingShutterMs / 1000.0;
  const double depthSeconds = options_.depthTimeOffsetMs / 1000.0;
  const Eigen::Vector3d ray = point.normalized();
  const Eigen::Matrix3d alongRay = ray * ray.transpose();
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - alongRay;
  Eigen::Matrix<double, 3, 6> dMotion;  // d(v + ω × p)/d(v, ω)
  dMotion.leftCols<3>() = Eigen::Matrix3d::Identity();
  dMotion.rightCols<3>() << 0, point.z(), -point.y(), -point.z(), 0, point.x(), point.y(),
      -point.x(), 0;  // -[p]×
  return (rowSeconds * across + depthSeconds * alongRay) * dMotion;
}

void SensorTiming::compensate(FeatureSet& features, const RgbdFrame& frame, const Pose& motion,
                              double motionMs) const {
  if (!enabled() || !(motionMs > 0)) return;
  const CameraIntrinsics& K = frame.intrinsics();
  const double rows = frame.grey().rows;
  // Camera at the depth image's instant, relative to the frame's time.
  const Pose depthCamera = interpolate(motion, options_.depthTimeOffsetMs / motionMs);
  const Pose frameFromDepth = depthCamera, depthFromFrame = depthCamera.inverse();
  for (size_t i = 0; i < features.size(); ++i) {
    const cv::Point2f px = features.keypoints[i].pt;
    // The row's exposure time, as a fraction of a frame period from the frame's (mid-readout).
    const double rowMotion = rowFraction(px.y, rows) * options_.rollingShutterMs / motionMs;
    const Pose frameFromRow = interpolate(motion, rowMotion);
    const Eigen::Vector2d undistorted = K.undistortPixel(px.x, px.y);
    const Eigen::Vector3d ray = K.backProject(undistorted.x(), undistorted.y(), 1.0);
    // Depth along the colour ray: first guess the one measured at the same pixel, then read it
    // where the depth camera saw the point (twice: the guess moves the pixel a little).
    double z = features.points[i].z();
    std::optional<Eigen::Vector3d> seenByDepth;
    for (int iteration = 0; iteration < 2; ++iteration) {
      const Eigen::Vector3d q = depthFromFrame * (frameFromRow * (ray * z));
      if (!(q.z() > 0)) break;
      const Eigen::Vector2d ideal = K.project(q);
      const Eigen::Vector2d pixel = K.distortPixel(ideal.x(), ideal.y());  // as the image has it
      const auto p = frame.backProject(pixel.x(), pixel.y());
      if (!p) break;
      seenByDepth = p;
      z = (frameFromRow.inverse() * (frameFromDepth * *p)).z();
      if (!(z > 0)) break;
    }
    if (seenByDepth) features.points[i] = frameFromDepth * *seenByDepth;
  }
}

}  // namespace slamdunk
