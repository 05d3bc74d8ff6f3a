#include <slamdunk/tracking/DepthNoiseModel.h>
#include <slamdunk/tracking/PoseRefinement.h>

#include <gtest/gtest.h>

#include <random>

using namespace slamdunk;

namespace {

/// Depth image of a corner (floor and two walls meeting 2 m in front of the camera), seen by a
/// camera at `pose` (world <- camera), rendered by ray casting so the geometry is exact.
cv::Mat renderCorner(const CameraIntrinsics& K, const Pose& pose) {
  cv::Mat depth(K.height, K.width, CV_32F, cv::Scalar(0));
  const Eigen::Vector3d planes[3] = {{0, -1, 0}, {-1, 0, 0}, {0, 0, -1}};  // normals
  const double offsets[3] = {0.8, 0.9, 2.5};  // n·x + d = 0 with d = offset: y=0.8, x=0.9, z=2.5
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d dirCam((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const Eigen::Vector3d o = pose.translation(), d = pose.linear() * dirCam;
      double best = 1e9;
      for (int k = 0; k < 3; ++k) {
        const double denom = planes[k].dot(d);
        if (std::abs(denom) < 1e-9) continue;
        const double t = -(planes[k].dot(o) + offsets[k]) / denom;
        if (t > 0 && t < best) best = t;
      }
      if (best < 1e8) depth.at<float>(v, u) = static_cast<float>(best);  // t is z (dirCam.z = 1)
    }
  return depth;
}

}  // namespace

TEST(PoseRefinement, DepthTermAloneRecoversAPerturbedPose) {
  CameraIntrinsics K;
  K.width = 160;
  K.height = 120;
  K.fx = K.fy = 130;
  K.cx = 79.5;
  K.cy = 59.5;
  const Pose reference = Pose::Identity();
  Pose truth = Pose::Identity();
  truth.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, 1, 0.2).normalized()).matrix();
  truth.translation() = Eigen::Vector3d(0.04, -0.02, 0.05);

  DepthAlignmentTerm term;
  term.referenceDepth = renderCorner(K, reference);
  term.referenceIntrinsics = K;
  term.worldFromReference = reference;
  term.maxDistance = 0.1;
  const cv::Mat current = renderCorner(K, truth);
  for (int v = 2; v < K.height; v += 4)
    for (int u = 2; u < K.width; u += 4)
      if (const float z = current.at<float>(v, u); z > 0)
        term.framePoints.push_back(K.backProject(u, v, z));

  Pose start = truth;  // off by 2 cm and about 1 degree
  start.translation() += Eigen::Vector3d(0.02, 0.01, -0.01);
  start.linear() = Eigen::AngleAxisd(0.015, Eigen::Vector3d::UnitY()).matrix() * start.linear();
  PoseRefinementOptions o;
  o.iterations = 15;
  const Pose refined = refinePose(start, {}, o, &term);
  EXPECT_LT(translationDistance(refined, truth), 0.002);
  EXPECT_LT(rotationDistance(refined, truth), 0.002);
  EXPECT_GT(translationDistance(start, truth), 0.02);
}

TEST(PoseRefinement, AnisotropicFeatureTermHandlesLargeNoiseAlongRays) {
  // Points with large noise (3 σ_z, centimetres) along their rays only: weighted by the
  // ray-aligned covariance, the pose is still found to millimetres.
  const DepthNoiseModel noise;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5), z(1.0, 4.0);
  std::normal_distribution<double> g(0, 1);
  Pose truth = Pose::Identity();
  truth.translation() = Eigen::Vector3d(0.1, 0.0, 0.2);
  std::vector<PosePair> pairs;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), z(rng));
    const Eigen::Vector3d noisy = p + p.normalized() * (3 * noise.depthSigma(p.z()) * g(rng));
    PosePair pp{noisy, truth * p, noise.covariance(p) * 9, Eigen::Matrix3d::Identity() * 1e-8};
    pairs.push_back(pp);
  }
  const Pose refined = refinePose(Pose::Identity(), pairs);
  EXPECT_LT(translationDistance(refined, truth), 0.005);
  EXPECT_LT(rotationDistance(refined, truth), 0.002);
}
