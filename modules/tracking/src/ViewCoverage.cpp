#include <slamdunk/tracking/ViewCoverage.h>

#include <cmath>

namespace slamdunk {

namespace {

/// What one keyframe needs to judge a point: where it is and what its depth shows.
struct KeyframeView {
  Pose worldToCamera;
  Eigen::Vector3d centre;
  KeyframePtr keyframe;
};

/// The keyframe's depth (metres) at the optical-frame point's pixel; 0 where it has none.
double depthAt(const Keyframe& kf, const Eigen::Vector2d& uv) {
  if (kf.depthSmall.empty() || kf.depthSmallStride < 1) return 0;
  const int c = static_cast<int>(uv.x()) / kf.depthSmallStride;
  const int r = static_cast<int>(uv.y()) / kf.depthSmallStride;
  if (r < 0 || c < 0 || r >= kf.depthSmall.rows || c >= kf.depthSmall.cols) return 0;
  if (kf.depthSmall.type() == CV_16F) return float(kf.depthSmall.at<cv::float16_t>(r, c));
  return kf.depthSmall.at<float>(r, c);
}

}  // namespace

double ViewCoverage::coveredShare(const std::vector<Eigen::Vector3d>& points, const Pose& frame,
                                  const KeyframeGraph& graph,
                                  const std::vector<KeyframeId>& keyframes) const {
  if (points.empty()) return 0;
  std::vector<KeyframeView> views;
  for (KeyframeId id : keyframes) {
    const Pose T = graph.pose(id);
    views.push_back({T.inverse(), T.translation(), graph.keyframe(id)});
  }
  const double cosMaxAngle = std::cos(options_.maxViewAngleDeg * M_PI / 180);
  const Eigen::Vector3d frameCentre = frame.translation();
  size_t covered = 0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d X = frame * p;
    const Eigen::Vector3d fromFrame = X - frameCentre;
    const double frameDistance = fromFrame.norm();
    for (const KeyframeView& v : views) {
      const Eigen::Vector3d c = v.worldToCamera * X;
      if (c.z() <= 0.1) continue;
      const CameraIntrinsics& K = v.keyframe->intrinsics;
      const Eigen::Vector2d uv = K.project(c);
      if (uv.x() < 0 || uv.y() < 0 || uv.x() >= K.width || uv.y() >= K.height) continue;
      const Eigen::Vector3d fromKeyframe = X - v.centre;
      const double distance = fromKeyframe.norm();
      const double ratio = distance / frameDistance;
      if (ratio > options_.maxDistanceRatio || ratio * options_.maxDistanceRatio < 1) continue;
      if (fromKeyframe.dot(fromFrame) < cosMaxAngle * distance * frameDistance) continue;
      // Hidden behind a nearer surface in the keyframe (beyond the depth's noise).
      const double d = depthAt(*v.keyframe, uv);
      if (d > 0 && c.z() > d + std::max(0.05, 0.03 * d)) continue;
      ++covered;
      break;
    }
  }
  return double(covered) / double(points.size());
}

}  // namespace slamdunk
