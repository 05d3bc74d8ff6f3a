#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/SensorTiming.h>

#include "RenderPlanes.h"

#include <gtest/gtest.h>

#include <random>

using namespace slamdunk;

namespace {
cv::Mat renderCorner(const CameraIntrinsics& K, const Pose& pose) {
  return test::renderPlanes(K, pose, test::cornerPlanes());
}
}  // namespace

TEST(PoseRefinement, DepthTermAloneRecoversAPerturbedPose) {
  const CameraIntrinsics K = test::smallCamera();
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

TEST(PoseRefinement, VelocityOfARollingShutterFrameIsEstimatedWithItsPose) {
  // A camera turning at 60 deg/s and moving at 0.3 m/s, its rows exposed over 20 ms: each
  // feature's point was taken from a camera moved by τ·ν, and compensated with no velocity at
  // all. The joint refinement finds the pose and the velocity (and the velocity then moves
  // the points to the frame's instant), from a wide prior at zero.
  const DepthNoiseModel noise;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5), z(1.0, 4.0), row(0, 480);
  std::normal_distribution<double> g(0, 1);
  const SensorTiming timing({20.0, 0.0});
  Twist velocity;
  velocity << 0.3, -0.1, 0.05, 0.2, 1.0, -0.3;  // m/s, rad/s (1.0 rad/s = 57 deg/s)
  Pose truth = Pose::Identity();
  truth.translation() = Eigen::Vector3d(0.05, -0.02, 0.1);
  std::vector<PosePair> pairs;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), z(rng));  // where it is at the frame's instant
    const Eigen::Matrix<double, 3, 6> J = timing.velocityJacobian(p, row(rng), 480);
    // As measured: moved back by the velocity its row saw, with pixel-sized noise.
    const Eigen::Vector3d measured =
        p - J * velocity + 0.0005 * p.z() * Eigen::Vector3d(g(rng), g(rng), 0);
    PosePair pair{measured, truth * p, noise.covariance(p), Eigen::Matrix3d::Identity() * 1e-8};
    pair.velocityJacobian = J;
    pairs.push_back(pair);
  }
  FrameVelocity v;
  v.priorSigma << 1, 1, 1, 5, 5, 5;
  const Pose refined = refinePose(Pose::Identity(), pairs, {}, nullptr, &v);
  EXPECT_LT(translationDistance(refined, truth), 0.001);
  EXPECT_LT(rotationDistance(refined, truth), 0.0005);
  EXPECT_LT((v.estimate.tail<3>() - velocity.tail<3>()).norm(), 0.05) << v.estimate.transpose();
  // Without the velocity, the same points give a pose off by millimetres.
  const Pose ignoring = refinePose(Pose::Identity(), pairs);
  EXPECT_GT(translationDistance(ignoring, truth), 3 * translationDistance(refined, truth));
}
