// Registration by depth alone (textureless or dark frames) on exact ray-cast depth: it recovers
// a motion where the geometry holds the pose, and refuses where it cannot (a wall on a floor
// lets the camera slide along the wall; views that do not overlap).

#include <slamdunk/tracking/DepthOnlyRegistration.h>

#include "RenderPlanes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

using namespace slamdunk;

namespace {

/// Reference keyframe at the origin, current frame at `truth`, both seeing `planes`.
DepthAlignmentTerm termFor(const Pose& truth, const std::vector<test::Plane>& planes) {
  const CameraIntrinsics K = test::smallCamera();
  DepthAlignmentTerm term;
  term.referenceDepth = test::renderPlanes(K, Pose::Identity(), planes);
  term.referenceIntrinsics = K;
  const cv::Mat current = test::renderPlanes(K, truth, planes);
  for (int v = 2; v < K.height; v += 4)
    for (int u = 2; u < K.width; u += 4)
      if (const float z = current.at<float>(v, u); z > 0)
        term.framePoints.push_back(K.backProject(u, v, z));
  return term;
}

}  // namespace

TEST(FitPlaneNormals, EveryPlanePixelGetsItsPlaneNormal) {
  const CameraIntrinsics K = test::smallCamera();
  const auto planes = test::cornerPlanes();
  const cv::Mat depth = test::renderPlanes(K, Pose::Identity(), planes);
  const cv::Mat normals = fitPlaneNormals(depth, K, 2);
  ASSERT_EQ(normals.type(), CV_32FC3);
  size_t valid = 0, withNormal = 0, offByHalfADegree = 0, offByFiveDegrees = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      if (!(depth.at<float>(v, u) > 0)) continue;
      ++valid;
      const cv::Vec3f f = normals.at<cv::Vec3f>(v, u);
      const Eigen::Vector3d n(f[0], f[1], f[2]);
      if (n.squaredNorm() < 0.5) continue;  // a crease between two planes: no normal
      ++withNormal;
      double best = 0;
      for (const auto& p : planes) best = std::max(best, std::abs(n.dot(p.normal)));
      if (best < std::cos(0.5 * M_PI / 180)) ++offByHalfADegree;
      if (best < std::cos(5 * M_PI / 180)) ++offByFiveDegrees;
    }
  EXPECT_GT(withNormal, 0.9 * valid);  // only the creases lack one
  // Windows that reach a little over a crease still pass as planes, tilted: a few, by little.
  EXPECT_LT(offByHalfADegree, 0.05 * withNormal) << offByHalfADegree << " of " << withNormal;
  EXPECT_LT(offByFiveDegrees, 0.01 * withNormal) << offByFiveDegrees << " of " << withNormal;
}

TEST(DepthOnlyRegistration, RecoversAMotionInACorner) {
  // 6 cm and 4 degrees from the prediction (the reference pose): a fast hand-held motion.
  const Pose truth = poseFromAxisAngle({0.2, 1, 0.1}, 4 * M_PI / 180, {0.04, -0.02, 0.04});
  const DepthOnlyResult r =
      registerByDepthOnly(Pose::Identity(), termFor(truth, test::cornerPlanes()));
  ASSERT_TRUE(r.success) << r.failure;
  EXPECT_LT(translationDistance(r.pose, truth), 0.001);
  EXPECT_LT(rotationDistance(r.pose, truth), 0.1 * M_PI / 180);
  EXPECT_GT(r.associatedFraction, 0.8);
  EXPECT_LT(r.rmsResidual, 0.001);
  EXPECT_GT(r.constraint, 0.1);
}

TEST(DepthOnlyRegistration, RefusesAWallOnAFloor) {
  // Floor and the wall ahead only: nothing holds the camera along the wall (x).
  const std::vector<test::Plane> planes = {test::cornerPlanes()[0], test::cornerPlanes()[2]};
  const Pose truth = poseFromAxisAngle({0, 1, 0}, 0, {0.05, 0, 0});
  const DepthOnlyResult r = registerByDepthOnly(Pose::Identity(), termFor(truth, planes));
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.failure.find("weakest direction"), std::string::npos) << r.failure;
  EXPECT_LT(r.constraint, 0.01);
}

TEST(DepthOnlyRegistration, RefusesViewsThatDoNotOverlap) {
  // Turned 90 degrees away: the frame sees the other wall, the reference does not.
  const Pose truth = poseFromAxisAngle({0, 1, 0}, M_PI / 2, {0, 0, 0});
  const DepthOnlyResult r =
      registerByDepthOnly(Pose::Identity(), termFor(truth, test::cornerPlanes()));
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.failure.find("overlap"), std::string::npos) << r.failure;
}

TEST(DepthOnlyRegistration, NoDepthIsAnError) {
  DepthAlignmentTerm empty;
  const DepthOnlyResult r = registerByDepthOnly(Pose::Identity(), empty);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.failure.find("no depth"), std::string::npos) << r.failure;
}
