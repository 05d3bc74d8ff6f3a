#include <slamdunk/core/Pose.h>

#include <gtest/gtest.h>
#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <limits>

using namespace slamdunk;

TEST(Pose, OpticalAxisIsSensorForward) {
  // A point 1 m ahead of the optical frame (z) is 1 m ahead of MRPT's sensor frame (x);
  // optical x (right) is sensor -y (left), optical y (down) is sensor -z (up).
  const Pose& T = opticalInSensor();
  EXPECT_TRUE((T * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(1, 0, 0)).norm() < 1e-12);
  EXPECT_TRUE((T * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(0, -1, 0)).norm() < 1e-12);
  EXPECT_TRUE((T * Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-12);
}

TEST(Pose, MatchesMrptCompositionFromNotes) {
  // The notes' recipe: T_w_sensor = T_w_opt + (-CPose3D(0,0,0,-90deg,0,-90deg)).
  const Pose T_w_opt = poseFromTranslationQuaternion(1, 2, 3, 0.1, -0.2, 0.3, 0.9);
  const mrpt::poses::CPose3D c(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  const mrpt::poses::CPose3D expected = toCPose3D(T_w_opt) + (-c);
  const Pose got = opticalToSensorPose(T_w_opt);
  EXPECT_LT((got.matrix() - fromCPose3D(expected).matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((sensorToOpticalPose(got).matrix() - T_w_opt.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Pose, CPose3DRoundTrip) {
  const Pose p = poseFromTranslationQuaternion(-0.5, 0.25, 2, 0.3, 0.1, -0.4, 0.8);
  EXPECT_LT((fromCPose3D(toCPose3D(p)).matrix() - p.matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Pose, QuaternionIsNormalisedAndBadValuesRejected) {
  const Pose p = poseFromTranslationQuaternion(0, 0, 0, 0, 0, 0, 2.0);
  EXPECT_TRUE(isValidPose(p));
  EXPECT_THROW(poseFromTranslationQuaternion(0, 0, 0, 0, 0, 0, 0), std::invalid_argument);
  EXPECT_THROW(poseFromTranslationQuaternion(std::nan(""), 0, 0, 0, 0, 0, 1),
               std::invalid_argument);
  EXPECT_THROW(
      poseFromTranslationQuaternion(0, 0, 0, 0, 0, 0, std::numeric_limits<double>::infinity()),
      std::invalid_argument);
  Pose bad = Pose::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_FALSE(isValidPose(bad));
}

TEST(Pose, AnglesAndDistances) {
  Pose a = Pose::Identity();
  Pose b = Pose::Identity();
  b.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(3, 4, 0);
  EXPECT_NEAR(rotationDistance(a, b), 0.3, 1e-12);
  EXPECT_NEAR(translationDistance(a, b), 5.0, 1e-12);
}
