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
    const double rowFraction = ((px.y + 0.5) / rows - 0.5) * options_.rollingShutterMs / motionMs;
    const Pose frameFromRow = interpolate(motion, rowFraction);
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
