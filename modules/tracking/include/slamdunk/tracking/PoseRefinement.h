#pragma once
// Refines a camera pose from 3D-3D inlier pairs by minimising the Mahalanobis distance under
// anisotropic depth noise (Gauss-Newton on SE(3), Huber-robust). Beyond the paper: RANSAC's
// isotropic least squares lets the noisy depth of far points pull the pose along their rays.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/core/RgbdFrame.h>

#include <opencv2/core.hpp>

#include <Eigen/Core>
#include <vector>

namespace slamdunk {

/// A camera's velocity: (v in m/s, ω in rad/s), in its own frame.
using Twist = Eigen::Matrix<double, 6, 1>;

struct PosePair {
  Eigen::Vector3d source;     ///< in the camera being posed
  Eigen::Vector3d target;     ///< in the world
  Eigen::Matrix3d sourceCov;  ///< in the camera's frame
  Eigen::Matrix3d targetCov;  ///< in the world frame
  /// How `source` moves with the camera's velocity (d source / d twist): non-zero for a point
  /// measured off the frame's instant (SensorTiming::velocityJacobian).
  Eigen::Matrix<double, 3, 6> velocityJacobian = Eigen::Matrix<double, 3, 6>::Zero();
};

/// The camera's velocity during the frame, estimated with its pose. A rolling shutter exposes
/// each row at its own time and depth comes at yet another, so each feature's point depends on
/// how the camera moved during the frame: that makes the velocity observable in one frame,
/// where a motion model only extrapolates it from earlier frames (a shaking hand reverses
/// within a few frames). The motion model's prediction is a prior, which also holds the
/// velocity where the timing alone cannot (a global shutter).
struct FrameVelocity {
  Twist compensated = Twist::Zero();  ///< the velocity the sources' points were moved with
  Twist prior = Twist::Zero();        ///< the motion model's prediction
  Twist priorSigma = Twist::Ones();   ///< its standard deviation
  Twist estimate = Twist::Zero();     ///< out: the refined velocity
};

struct PoseRefinementOptions {
  int iterations = 6;
  double huberSigmas = 2.5;  ///< residuals beyond this many standard deviations are down-weighted
};

/// Dense term: points of the current frame's depth aligned point-to-plane with the depth of a
/// reference keyframe (projective association). Beyond the paper: it constrains the pose where
/// features are few or imprecise, with the depth sensor's own geometry.
struct DepthAlignmentTerm {
  std::vector<Eigen::Vector3d> framePoints;  ///< subsampled current-frame points, camera frame
  cv::Mat referenceDepth;                    ///< CV_32F metres, subsampled
  CameraIntrinsics referenceIntrinsics;      ///< scaled to referenceDepth's resolution
  Pose worldFromReference = Pose::Identity();
  double maxDistance = 0.05;  ///< metres: farther associations are not the same surface
  double weight = 1.0;        ///< relative to the feature term
  /// Reference normals from central differences (±1 pixel) instead of one-sided ones: steadier
  /// on noisy depth (tracking alone drifts far less), see
  /// TrackerOptions::depthAlignmentCentralNormals.
  bool centralNormals = false;
  /// Optional reference normals (CV_32FC3, one per referenceDepth pixel, zero where none), e.g.
  /// from fitPlaneNormals(); they replace the normals from neighbouring pixels.
  cv::Mat referenceNormals;
};

/// One point-to-plane association of the depth term, in the reference keyframe's frame.
struct DepthCorrespondence {
  Eigen::Vector3d referencePoint;  ///< on the reference surface, reference camera frame
  Eigen::Vector3d framePoint;      ///< current camera frame
  Eigen::Vector3d normal;          ///< of the reference surface, reference camera frame
  double sigma = 0;                ///< metres, standard deviation of the point-to-plane distance
  double residual = 0;             ///< metres, point-to-plane distance at the pose it was made for
};

/// The associations the depth term uses for a camera pose T (world <- camera).
std::vector<DepthCorrespondence> depthCorrespondences(const Pose& T, const DepthAlignmentTerm& d);
/// Share of the frame's depth samples that land on the reference's depth (within twice the
/// gate along the reference's ray) at pose T: the overlap of the two views, whether or not a
/// normal exists there.
double depthOverlap(const Pose& T, const DepthAlignmentTerm& d);

/// Returns the refined T (maps source to target), starting from `initial`. With a depth term,
/// both terms are minimised jointly.
/// With `velocity`, the camera's velocity is refined jointly (sources move by their
/// velocityJacobian as it changes) and returned in velocity->estimate.
Pose refinePose(const Pose& initial, const std::vector<PosePair>& pairs,
                const PoseRefinementOptions& options = {},
                const DepthAlignmentTerm* depth = nullptr, FrameVelocity* velocity = nullptr);

/// Normals of a depth image (CV_32F metres) from a plane fitted to each pixel's window of
/// ±radius pixels; zero where the window holds too few points or no plane (an edge, a corner).
/// Steadier than differences of neighbours on quantised sensor depth, whose steps tilt those by
/// tens of degrees, and a staircase floor tilts them all the same way.
cv::Mat fitPlaneNormals(const cv::Mat& depth, const CameraIntrinsics& K, int radius);

/// Subsamples a depth image (keeps the pixel at each stride step; 0 stays invalid).
cv::Mat subsampleDepth(const cv::Mat& depth, int stride);
/// Intrinsics of an image subsampled by stride (pixel centres stay consistent), without the
/// lens distortion: the depth term projects and back-projects as a pinhole camera.
CameraIntrinsics scaleIntrinsics(const CameraIntrinsics& K, int stride);
/// A depth image of camera K, subsampled by stride, resampled onto the pinhole grid of
/// scaleIntrinsics(K, stride) (interpolatedDepth where the lens put each pixel's ray): the same
/// image when K has no distortion. Without it, a lens like a Kinect's (TUM fr1: k1 0.26) puts
/// the depth near the border several percent off its ray.
cv::Mat undistortedDepth(const cv::Mat& depth, const CameraIntrinsics& K, int stride);
/// The frame's depth, back-projected every `stride` pixels up to `maxDepth` (camera frame, lens
/// distortion taken out): the samples a depth term aligns.
std::vector<Eigen::Vector3d> depthSamples(const RgbdFrame& frame, int stride, double maxDepth);

}  // namespace slamdunk
