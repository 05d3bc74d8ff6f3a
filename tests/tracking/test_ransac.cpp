#include <slamdunk/tracking/RansacAbsoluteOrientation.h>

#include <gtest/gtest.h>

#include <random>

using namespace slamdunk;

namespace {
struct PointPairs {
  std::vector<Eigen::Vector3d> src, dst;
  std::vector<bool> outlier;
};
PointPairs makePairs(const Pose& T, size_t n, double outlierFraction, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5), z(0.8, 4.0), coin(0, 1);
  std::normal_distribution<double> g(0, noise);
  PointPairs p;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d s(u(rng), u(rng), z(rng));
    Eigen::Vector3d d = T * s + Eigen::Vector3d(g(rng), g(rng), g(rng));
    const bool bad = coin(rng) < outlierFraction;
    if (bad) d = Eigen::Vector3d(u(rng), u(rng), z(rng)) * 2;
    p.src.push_back(s);
    p.dst.push_back(d);
    p.outlier.push_back(bad);
  }
  return p;
}
Pose testPose() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.3, -0.1, 0.5);
  return T;
}
}  // namespace

TEST(Ransac, ExactFitOfFourPoints) {
  const Pose T = testPose();
  const auto p = makePairs(T, 4, 0, 0, 1);
  const Pose fit = fitRigidTransform(p.src, p.dst);
  EXPECT_LT((fit.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(Ransac, RecoversPoseWithHalfOutliers) {
  const Pose T = testPose();
  const auto p = makePairs(T, 300, 0.5, 0.003, 2);
  RansacOptions o;
  const RansacResult r = ransacAbsoluteOrientation(p.src, p.dst, o);
  ASSERT_TRUE(r.success);
  EXPECT_LT(translationDistance(r.transform, T), 0.003);
  EXPECT_LT(rotationDistance(r.transform, T), 0.002);
  size_t wrong = 0;
  for (size_t i = 0; i < p.src.size(); ++i) wrong += r.inliers[i] == p.outlier[i];
  EXPECT_LT(wrong, 10u);         // a few random outliers can land within the threshold
  EXPECT_LT(r.iterations, 200);  // adaptive: about 35 expected for w = 0.5, p = 0.99
}

TEST(Ransac, DeterministicForASeed) {
  const auto p = makePairs(testPose(), 200, 0.4, 0.005, 3);
  RansacOptions o;
  const RansacResult a = ransacAbsoluteOrientation(p.src, p.dst, o);
  const RansacResult b = ransacAbsoluteOrientation(p.src, p.dst, o);
  EXPECT_EQ(a.transform.matrix(), b.transform.matrix());
  EXPECT_EQ(a.inliers, b.inliers);
}

TEST(Ransac, FailsOnPureNoiseAndTooFewPoints) {
  const auto p = makePairs(testPose(), 100, 1.0, 0, 4);
  RansacOptions o;
  o.minInliers = 12;
  EXPECT_FALSE(ransacAbsoluteOrientation(p.src, p.dst, o).success);
  const auto few = makePairs(testPose(), 5, 0, 0, 5);
  EXPECT_FALSE(ransacAbsoluteOrientation(few.src, few.dst, o).success);
}

TEST(Ransac, WeightedRefitFavoursPreciseNearPoints) {
  // Near points are exact, far ones carry a common bias: weighting by depth noise ignores it.
  const Pose T = testPose();
  auto p = makePairs(T, 200, 0, 0, 6);
  std::vector<double> w;
  for (size_t i = 0; i < p.src.size(); ++i) {
    if (p.src[i].z() > 3.0) p.dst[i] += Eigen::Vector3d(0.01, 0, 0);
    w.push_back(p.src[i].z() > 3.0 ? 1e-3 : 1.0);
  }
  RansacOptions o;
  o.inlierThreshold = 0.05;
  const RansacResult weighted = ransacAbsoluteOrientation(p.src, p.dst, o, &w);
  const RansacResult plain = ransacAbsoluteOrientation(p.src, p.dst, o);
  ASSERT_TRUE(weighted.success && plain.success);
  EXPECT_LT(translationDistance(weighted.transform, T),
            0.5 * translationDistance(plain.transform, T));
}
