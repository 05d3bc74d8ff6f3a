// The landmark form of the local optimization (residual_form = landmarks): feature matches are
// followed from keyframe to keyframe into landmarks, each observed in pixels and depth with
// their own precisions. Synthetic keyframes measure a scene of points the way an RGB-D camera
// does: the keypoint's pixel is precise, the depth read there much less.
#include <slamdunk/optimization/LocalOptimizer.h>

#include "WalkPastAWall.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

using namespace slamdunk;

namespace {

constexpr double kFocal = 525.0;

/// Keyframes walking past a wall of points, each measuring the points it sees: pixel noise
/// `pixelSigma`, depth noise `noise.depthSigma(z)` along the viewing ray.
class RgbdScene {
 public:
  RgbdScene(int keyframes, const DepthNoiseModel& noise, unsigned seed = 3)
      : noise_(noise), rng_(seed) {
    points_ = test::pointsInBox(3000, {-1.5, -1.0, 1.2}, {0.15 * keyframes + 1.5, 1.0, 3.0}, rng_);
    for (int k = 0; k < keyframes; ++k) {
      truth_.push_back(
          test::wobblingPose({0.15 * k, 0.03 * std::sin(0.5 * k), 0.05 * std::cos(0.3 * k)},
                             6 * kDeg * std::sin(0.4 * k), 3 * kDeg * std::sin(0.6 * k)));
      measure(k);
    }
  }

  const Pose& truth(int k) const { return truth_[k]; }
  int size() const { return static_cast<int>(truth_.size()); }

  /// The keyframe as the graph holds it: its measured feature points, feature i = point i.
  KeyframePtr keyframe(int k) const {
    auto kf = std::make_shared<Keyframe>();
    kf->id = static_cast<KeyframeId>(k);
    kf->intrinsics.fx = kf->intrinsics.fy = kFocal;
    kf->intrinsics.cx = 320;
    kf->intrinsics.cy = 240;
    kf->intrinsics.width = 640;
    kf->intrinsics.height = 480;
    kf->features.points = measured_[k];
    return kf;
  }

  /// Matches of the points both keyframes see, with their feature indices.
  std::vector<PointMatch> matches(int i, int j) const {
    std::vector<PointMatch> out;
    for (size_t n = 0; n < points_.size(); ++n)
      if (visible(i, n) && visible(j, n)) {
        PointMatch m{measured_[i][n], measured_[j][n], 1.0};
        m.featureI = m.featureJ = static_cast<uint32_t>(n);
        out.push_back(m);
      }
    return out;
  }

  /// A chain graph: keyframe k linked to k-1 and k-2, starting at `start` (truth if null).
  std::shared_ptr<KeyframeGraph> graph(const std::vector<Pose>* start = nullptr) const {
    auto g = std::make_shared<KeyframeGraph>();
    for (int k = 0; k < size(); ++k) g->addKeyframe(keyframe(k), start ? (*start)[k] : truth_[k]);
    for (int k = 1; k < size(); ++k)
      for (int back = 1; back <= 2 && k - back >= 0; ++back)
        g->addMatches(k - back, k, matches(k - back, k));
    return g;
  }

  /// The truth, each pose but the first off by about 2 cm and 1 degree.
  std::vector<Pose> perturbed(unsigned seed) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Pose> out = truth_;
    for (size_t k = 1; k < out.size(); ++k) {
      Pose d = Pose::Identity();
      d.linear() =
          Eigen::AngleAxisd(1.0 * kDeg, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
              .toRotationMatrix();
      d.translation() = 0.02 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      out[k] = out[k] * d;
    }
    return out;
  }

  const Eigen::Vector3d& point(size_t n) const { return points_[n]; }
  bool visible(int k, size_t n) const { return visible_[k][n]; }

 private:
  void measure(int k) {
    std::normal_distribution<double> g(0, 1);
    measured_.emplace_back(points_.size(), Eigen::Vector3d::Zero());
    visible_.emplace_back(points_.size(), false);
    for (size_t n = 0; n < points_.size(); ++n) {
      const Eigen::Vector3d c = truth_[k].inverse() * points_[n];
      const double u = kFocal * c.x() / c.z(), v = kFocal * c.y() / c.z();
      if (!(c.z() > 0.5 && std::abs(u) < 320 && std::abs(v) < 240)) continue;
      // Only some of the points are features of this keyframe.
      if (std::uniform_real_distribution<double>(0, 1)(rng_) > 0.5) continue;
      const double un = u + noise_.pixelSigma * g(rng_), vn = v + noise_.pixelSigma * g(rng_);
      const double z = c.z() + noise_.depthSigma(c.z()) * g(rng_);
      measured_[k][n] = Eigen::Vector3d(un / kFocal * z, vn / kFocal * z, z);
      visible_[k][n] = true;
    }
  }

  DepthNoiseModel noise_;
  std::mt19937 rng_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<Pose> truth_;
  std::vector<std::vector<Eigen::Vector3d>> measured_;
  std::vector<std::vector<bool>> visible_;
};

/// A Kinect-like sensor: half a pixel of keypoint error, depth noise ~6 mm at 1 m.
DepthNoiseModel kinectLike() {
  DepthNoiseModel m;
  m.pixelSigma = 0.5;
  m.depthSigmaQuadratic = 0.006;
  return m;
}

LocalOptimizerOptions landmarkOptions(const DepthNoiseModel& noise) {
  LocalOptimizerOptions o;
  o.residualForm = ResidualForm::Landmarks;
  o.noise = noise;
  o.rings = 100;  // the whole chain: keyframe 0 is the gauge
  return o;
}

/// Largest camera-centre error against the truth, with keyframe 0 where it truly is.
double worstError(const KeyframeGraph& g, const RgbdScene& scene) {
  double worst = 0;
  for (int k = 0; k < scene.size(); ++k)
    worst = std::max(worst, translationDistance(g.pose(k), scene.truth(k)));
  return worst;
}

}  // namespace

TEST(LandmarkBundleAdjustment, RecoversPosesFromPixelsAndNoisyDepth) {
  const DepthNoiseModel noise = kinectLike();
  const RgbdScene scene(8, noise);
  const auto start = scene.perturbed(11);
  auto landmarkGraph = scene.graph(&start);
  auto edgeGraph = scene.graph(&start);

  const auto rep = LocalOptimizer(landmarkOptions(noise)).optimize(*landmarkGraph, 0);
  ASSERT_TRUE(rep.usable) << rep.toString();
  EXPECT_GT(rep.landmarks, 500) << rep.toString();
  // The paper's cost on the same matches: 3D differences, depth noise taken for the whole error.
  LocalOptimizerOptions paper;
  paper.residualForm = ResidualForm::Edge;
  paper.rings = 100;
  ASSERT_TRUE(LocalOptimizer(paper).optimize(*edgeGraph, 0).usable);

  const double landmarkError = worstError(*landmarkGraph, scene);
  const double edgeError = worstError(*edgeGraph, scene);
  std::cout << "worst camera error: landmarks " << landmarkError * 1000 << " mm, 3D edges "
            << edgeError * 1000 << " mm (" << rep.toString() << ")\n";
  EXPECT_LT(landmarkError, 0.003);
  EXPECT_LT(landmarkError, 0.5 * edgeError) << "the pixels' precision is not used";
}

TEST(LandmarkBundleAdjustment, FollowsFeaturesAcrossKeyframes) {
  const RgbdScene scene(3, kinectLike());
  auto g = scene.graph();
  // Points seen by all three keyframes are one landmark with three observations; the rest
  // (seen by two) one with two.
  int three = 0, two = 0;
  for (size_t n = 0; n < 3000; ++n) {
    const int seen = scene.visible(0, n) + scene.visible(1, n) + scene.visible(2, n);
    three += seen == 3;
    two += seen == 2;
  }
  const auto rep = LocalOptimizer(landmarkOptions(kinectLike())).optimize(*g, 0);
  ASSERT_TRUE(rep.usable) << rep.toString();
  EXPECT_EQ(rep.landmarks, three + two);
  EXPECT_EQ(rep.observations, 3 * three + 2 * two);
}

TEST(LandmarkBundleAdjustment, TrackThroughAWrongMatchIsLeftOut) {
  const RgbdScene scene(2, kinectLike());
  auto g = scene.graph();
  const auto before = LocalOptimizer(landmarkOptions(kinectLike())).optimize(*scene.graph(), 0);
  // A wrong match joins feature a of keyframe 1 to feature b of keyframe 0 while a is already
  // matched to feature a of keyframe 0: that track reaches keyframe 0 twice.
  const auto m = scene.matches(0, 1);
  ASSERT_GE(m.size(), 2u);
  PointMatch wrong = m[0];
  wrong.featureI = m[1].featureI;
  wrong.pointI = m[1].pointI;
  g->addMatches(0, 1, {wrong});
  const auto after = LocalOptimizer(landmarkOptions(kinectLike())).optimize(*g, 0);
  ASSERT_TRUE(after.usable) << after.toString();
  // The two landmarks the wrong match joined are both dropped.
  EXPECT_EQ(after.landmarks, before.landmarks - 2);
}

TEST(LandmarkBundleAdjustment, RefinesTheFeaturePositions) {
  const DepthNoiseModel noise = kinectLike();
  const RgbdScene scene(6, noise);
  auto g = scene.graph();
  ASSERT_EQ(g->refinedPoints(2), nullptr);
  ASSERT_TRUE(LocalOptimizer(landmarkOptions(noise)).optimize(*g, 0).usable);
  const RefinedPoints refined = g->refinedPoints(2);
  ASSERT_NE(refined, nullptr);
  // The landmarks average their observations' depth noise: the refined points are nearer the
  // scene than what keyframe 2 measured.
  double measuredError = 0, refinedError = 0;
  int n = 0;
  const KeyframePtr kf = g->keyframe(2);
  for (size_t i = 0; i < kf->features.points.size(); ++i) {
    if (!scene.visible(2, i) || (!scene.visible(1, i) && !scene.visible(3, i))) continue;
    const Eigen::Vector3d truth = scene.truth(2).inverse() * scene.point(i);
    measuredError += (kf->features.points[i] - truth).squaredNorm();
    refinedError += ((*refined)[i] - truth).squaredNorm();
    ++n;
  }
  ASSERT_GT(n, 100);
  std::cout << "RMS point error in keyframe 2: measured " << 1000 * std::sqrt(measuredError / n)
            << " mm, refined " << 1000 * std::sqrt(refinedError / n) << " mm\n";
  EXPECT_LT(refinedError, 0.7 * measuredError);
}

TEST(LandmarkBundleAdjustment, ToleratesWrongMatches) {
  const DepthNoiseModel noise = kinectLike();
  const RgbdScene scene(6, noise);
  const auto start = scene.perturbed(5);
  auto g = scene.graph(&start);
  // Wrong matches between keyframes 2 and 3: features of points half a metre apart.
  const auto m = scene.matches(2, 3);
  std::vector<PointMatch> wrong;
  for (size_t k = 0; k + 40 < m.size() && wrong.size() < 30; k += 3) {
    PointMatch w = m[k];
    w.featureJ = m[k + 40].featureJ;
    w.pointJ = m[k + 40].pointJ;
    wrong.push_back(w);
  }
  g->addMatches(2, 3, wrong);
  const auto rep = LocalOptimizer(landmarkOptions(noise)).optimize(*g, 0);
  ASSERT_TRUE(rep.usable) << rep.toString();
  EXPECT_LT(worstError(*g, scene), 0.004) << rep.toString();
}

TEST(LandmarkBundleAdjustment, SameGraphGivesBitIdenticalResults) {
  const DepthNoiseModel noise = kinectLike();
  const RgbdScene scene(6, noise);
  const auto start = scene.perturbed(9);
  auto a = scene.graph(&start), b = scene.graph(&start);
  LocalOptimizerOptions o = landmarkOptions(noise);
  o.rings = 2;
  ASSERT_TRUE(LocalOptimizer(o).optimize(*a, 5).usable);
  ASSERT_TRUE(LocalOptimizer(o).optimize(*b, 5).usable);
  for (int k = 0; k < scene.size(); ++k)
    EXPECT_TRUE(a->pose(k).matrix() == b->pose(k).matrix()) << "keyframe " << k;
}
