// fitRigidMotion (ComponentMotion.h): the one motion of a moving part of the map that explains its matches with
// keyframes that stay, whatever the keyframes' own poses.

#include <slamdunk/optimization/ComponentMotion.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

using namespace slamdunk;

namespace {

Pose poseOf(double yawDegrees, const Eigen::Vector3d& t) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yawDegrees * M_PI / 180, Eigen::Vector3d(0.1, 1, 0.2).normalized())
                   .toRotationMatrix();
  p.translation() = t;
  return p;
}

/// `count` points seen by a staying keyframe and by a moving one, which the motion `truth` puts
/// where it should be.
AnchoredMatches loopSeeing(const Pose& fixedPose, const Pose& movingPoseAfter, const Pose& truth,
                           int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> lateral(-1.0, 1.0), depth(1.0, 4.0);
  AnchoredMatches loop;
  loop.fixedPose = fixedPose;
  loop.movingPose = truth.inverse() * movingPoseAfter;  // where it was before the move
  for (int i = 0; i < count; ++i) {
    PointMatch m;
    m.pointI = Eigen::Vector3d(lateral(rng), lateral(rng), depth(rng));
    m.pointJ = movingPoseAfter.inverse() * (fixedPose * m.pointI);
    loop.matches.push_back(m);
  }
  return loop;
}

}  // namespace

TEST(ComponentMotion, RecoversTheMotionOfTheMovingPartFromSeveralLoops) {
  std::mt19937 rng(3);
  const Pose truth = poseOf(4.0, {1.2, -0.3, 0.5});
  std::vector<AnchoredMatches> loops;
  loops.push_back(loopSeeing(poseOf(10, {0, 0, 0}), poseOf(14, {0.1, 0, 0.2}), truth, 40, rng));
  loops.push_back(loopSeeing(poseOf(-30, {2, 0, 1}), poseOf(-25, {2.2, 0, 0.8}), truth, 150, rng));
  const Pose initial = poseOf(3.0, {1.0, -0.2, 0.6});  // one loop's estimate, a little off
  const std::optional<Pose> fitted = fitRigidMotion(loops, initial);
  ASSERT_TRUE(fitted);
  EXPECT_LT(translationDistance(*fitted, truth), 1e-6);
  EXPECT_LT(rotationDistance(*fitted, truth), 1e-6);
}

TEST(ComponentMotion, AFewMatchesDoNotDetermineAMotion) {
  std::mt19937 rng(4);
  const Pose truth = poseOf(2.0, {0.5, 0, 0});
  std::vector<AnchoredMatches> loops{
      loopSeeing(Pose::Identity(), poseOf(1, {0.1, 0, 0}), truth, 2, rng)};
  EXPECT_FALSE(fitRigidMotion(loops, Pose::Identity()));
  EXPECT_FALSE(fitRigidMotion({}, Pose::Identity()));
}
