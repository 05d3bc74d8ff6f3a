#include <slamdunk/eval/RigidAlignment.h>

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

using slamdunk::eval::RigidAlignment;

namespace {

std::vector<Eigen::Vector3d> randomPoints(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<Eigen::Vector3d> pts(n);
  for (auto& p : pts) p = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return pts;
}

}  // namespace

TEST(RigidAlignment, RecoversKnownRotationAndTranslation) {
  const std::vector<Eigen::Vector3d> source = randomPoints(50, 1);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(0.3, -1.0, 0.4).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(1.5, -0.25, 3.0);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(R * p + t);

  const RigidAlignment a = RigidAlignment::compute(source, target);
  EXPECT_LT((a.rotation - R).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((a.translation - t).norm(), 1e-12);
  EXPECT_LT((a.transform() * source[7] - target[7]).norm(), 1e-12);
}

// A mirror image is fitted perfectly only by a reflection; the result must still be a proper
// rotation (det +1), and then it cannot fit exactly.
TEST(RigidAlignment, NeverReturnsAReflection) {
  const std::vector<Eigen::Vector3d> source = randomPoints(30, 2);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(Eigen::Vector3d(-p.x(), p.y(), p.z()));

  const RigidAlignment a = RigidAlignment::compute(source, target);
  EXPECT_NEAR(a.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((a.rotation.transpose() * a.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  double residual = 0;
  for (std::size_t i = 0; i < source.size(); ++i)
    residual += (a.apply(source[i]) - target[i]).squaredNorm();
  EXPECT_GT(residual, 1e-3);
}

// Planar points: the cross-covariance has a zero singular value, where an uncorrected SVD
// solution may come out as a reflection.
TEST(RigidAlignment, PlanarPointsGiveProperRotation) {
  std::vector<Eigen::Vector3d> source = randomPoints(20, 3);
  for (auto& p : source) p.z() = 0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(R * p);
  const RigidAlignment a = RigidAlignment::compute(source, target);
  EXPECT_NEAR(a.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((a.rotation - R).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(RigidAlignment, RejectsTooFewOrMismatchedPoints) {
  const std::vector<Eigen::Vector3d> two = randomPoints(2, 4), three = randomPoints(3, 5);
  EXPECT_THROW(RigidAlignment::compute(two, two), std::invalid_argument);
  EXPECT_THROW(RigidAlignment::compute(three, two), std::invalid_argument);
  EXPECT_NO_THROW(RigidAlignment::compute(three, three));
}
