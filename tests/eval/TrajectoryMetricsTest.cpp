#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/TrajectoryMetrics.h>

#include <TestData.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace slamdunk;
using namespace slamdunk::eval;

namespace {

Pose makePose(const Eigen::Vector3d& t, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Pose p = Pose::Identity();
  p.linear() = R;
  p.translation() = t;
  return p;
}

/// A smooth hand-held-like camera path: n poses at `rate` Hz.
Trajectory syntheticTrajectory(std::size_t n, double rate, double t0 = 100.0) {
  Trajectory traj;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / rate;
    const Eigen::Vector3d pos(2.0 * std::sin(0.3 * t), 0.5 * std::sin(0.7 * t),
                              1.5 * std::cos(0.2 * t) + 0.1 * t);
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(0.4 * std::sin(0.5 * t), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.2 * std::cos(0.3 * t), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    traj.push_back({t0 + t, makePose(pos, R)});
  }
  return traj;
}

/// The same trajectory seen from another world frame: every pose left-multiplied by T.
Trajectory transformed(const Trajectory& traj, const Pose& T) {
  Trajectory out = traj;
  for (StampedPose& p : out) p.pose = T * p.pose;
  return out;
}

Pose someRigidTransform() {
  return makePose(Eigen::Vector3d(3.0, -1.0, 0.5),
                  Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix());
}

void expectSelfConsistent(const Trajectory& gt) {
  const TrajectoryEvaluation ev =
      TrajectoryMetrics::evaluate(gt, transformed(gt, someRigidTransform()));
  EXPECT_EQ(ev.pairs, gt.size());
  EXPECT_EQ(ev.unmatchedEstimatePoses, 0u);
  EXPECT_LT(ev.ate.stats.rmse, 1e-9);
  EXPECT_LT(ev.ate.stats.max, 1e-9);
  ASSERT_TRUE(ev.rpe.valid) << ev.rpe.reason;
  EXPECT_GT(ev.rpe.pairs, 0u);
  EXPECT_LT(ev.rpe.translation.max, 1e-9);
  // acos((trace - 1) / 2) near 1 resolves angles only to ~1e-8 rad.
  EXPECT_LT(ev.rpe.rotationDegrees.max, 1e-5);
  // A trajectory turns exactly as much as itself about every axis it turns about.
  for (int axis = 0; axis < 3; ++axis)
    if (std::isfinite(ev.rpe.rotationScale[axis]))
      EXPECT_NEAR(ev.rpe.rotationScale[axis], 1.0, 1e-9) << "axis " << axis;
}

}  // namespace

TEST(ErrorStatistics, MatchesNumpyConventions) {
  const ErrorStatistics s = ErrorStatistics::compute({4, 1, 3, 2});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);           // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std (numpy's default)
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(ErrorStatistics::compute({5, 1, 3}).median, 3);
  // numpy.percentile({1..4}, 95) = 1 + 0.95 * 3 (linear between ranks).
  EXPECT_DOUBLE_EQ(s.p95, 3.85);
  EXPECT_DOUBLE_EQ(s.p99, 3.97);
  std::vector<double> hundred;
  for (int i = 100; i >= 1; --i) hundred.push_back(i);
  EXPECT_DOUBLE_EQ(ErrorStatistics::compute(hundred).p95, 95.05);
}

TEST(TrajectoryMetrics, SyntheticGroundTruthAgainstItselfTransformed) {
  expectSelfConsistent(syntheticTrajectory(900, 30.0));
}

TEST(TrajectoryMetrics, TumGroundTruthAgainstItselfTransformed) {
  SLAMDUNK_REQUIRE_DATA(path, "tum/fr1_desk_9f/groundtruth.txt");
  const Trajectory gt = readTumTrajectory(path);
  ASSERT_GT(gt.size(), 1000u);
  expectSelfConsistent(gt);
}

TEST(TrajectoryMetrics, SevenScenesGroundTruthAgainstItselfTransformed) {
  SLAMDUNK_REQUIRE_DATA(path, "7scenes/seq-1000f/groundtruth.txt");
  const Trajectory gt = readTumTrajectory(path);
  ASSERT_EQ(gt.size(), 1000u);
  expectSelfConsistent(gt);
}

// Hand computation. Ground-truth positions (+-1,0,0), (0,+-1,0), (0,0,1); the estimate raises
// the x pair by 0.1, lowers the y pair by 0.05, leaves (0,0,1), and is then moved rigidly.
// The cross-covariance stays diagonal positive, so the best rotation is the identity (in the
// estimate's own frame) and the translation removes the mean error (0, 0, 0.02): errors are
// 0.08, 0.08, 0.07, 0.07, 0.02 m.
TEST(TrajectoryMetrics, HandComputedAte) {
  const std::vector<Eigen::Vector3d> g = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  const std::vector<Eigen::Vector3d> e = {
      {0, 0, 0.1}, {0, 0, 0.1}, {0, 0, -0.05}, {0, 0, -0.05}, {0, 0, 0}};
  const Pose T = someRigidTransform();
  Trajectory gt, est;
  for (std::size_t i = 0; i < g.size(); ++i) {
    gt.push_back({1.0 + i, makePose(g[i])});
    est.push_back({1.0 + i, T * makePose(g[i] + e[i])});
  }
  const TrajectoryEvaluation ev = TrajectoryMetrics::evaluate(gt, est);
  ASSERT_EQ(ev.pairs, 5u);
  const ErrorStatistics& s = ev.ate.stats;
  EXPECT_NEAR(s.rmse, std::sqrt((2 * 0.0064 + 2 * 0.0049 + 0.0004) / 5), 1e-12);
  EXPECT_NEAR(s.mean, (0.16 + 0.14 + 0.02) / 5, 1e-12);
  EXPECT_NEAR(s.median, 0.07, 1e-12);
  EXPECT_NEAR(s.min, 0.02, 1e-12);
  EXPECT_NEAR(s.max, 0.08, 1e-12);
  // The alignment undoes T (up to the 0.02 m shift along the estimate's z).
  EXPECT_LT((ev.ate.alignment.rotation - T.linear().transpose()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(TrajectoryMetrics, AteNeedsThreePairs) {
  Trajectory gt, est;
  for (int i = 0; i < 2; ++i) {
    gt.push_back({double(i), makePose(Eigen::Vector3d(i, 0, 0))});
    est.push_back({double(i), makePose(Eigen::Vector3d(i, 0, 0))});
  }
  EXPECT_THROW(TrajectoryMetrics::evaluate(gt, est), std::runtime_error);
}

TEST(TrajectoryMetrics, NoAssociatedPairsIsAnError) {
  const Trajectory gt = syntheticTrajectory(100, 30.0, 0.0);
  const Trajectory est = syntheticTrajectory(100, 30.0, 1000.0);
  try {
    TrajectoryMetrics::evaluate(gt, est);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no pose pairs associated"), std::string::npos)
        << e.what();
  }
}

// Estimated poses far from any ground-truth stamp (here: after the ground truth ends, and one
// 0.03 s off) are counted, and ATE uses only the associated ones.
TEST(TrajectoryMetrics, CountsEstimatedPosesWithoutGroundTruthPartner) {
  const Trajectory gt = syntheticTrajectory(300, 30.0);
  Trajectory est = syntheticTrajectory(310, 30.0);              // 10 poses past the gt's end
  est.push_back({est[5].timestamp + 0.5 / 30.0, est[5].pose});  // halfway between gt stamps
  const TrajectoryEvaluation ev = TrajectoryMetrics::evaluate(gt, est);
  EXPECT_EQ(ev.estimatePoses, 311u);
  EXPECT_EQ(ev.pairs, 300u);
  EXPECT_EQ(ev.unmatchedEstimatePoses, 11u);
  EXPECT_LT(ev.ate.stats.rmse, 1e-9);
}

// Isotropic Gaussian noise of sigma on every position: the per-pose error is |n| with
// E|n|^2 = 3 sigma^2, and a 6-dof alignment on 20000 poses absorbs a negligible part of it.
TEST(TrajectoryMetrics, GaussianNoiseGivesSigmaSqrt3) {
  const double sigma = 0.01;
  const Trajectory gt = syntheticTrajectory(20000, 30.0);
  Trajectory est = transformed(gt, someRigidTransform());
  std::mt19937 rng(12345);
  std::normal_distribution<double> noise(0.0, sigma);
  for (StampedPose& p : est)
    p.pose.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));

  const TrajectoryEvaluation ev = TrajectoryMetrics::evaluate(gt, est);
  ASSERT_EQ(ev.pairs, 20000u);
  EXPECT_NEAR(ev.ate.stats.rmse, sigma * std::sqrt(3.0), 0.02 * sigma * std::sqrt(3.0));
  // Mean of a Maxwell distribution: 2 sigma sqrt(2 / pi).
  EXPECT_NEAR(ev.ate.stats.mean, 2 * sigma * std::sqrt(2 / M_PI), 0.02 * sigma);
}

// Five poses 0.5 s apart, ground truth moving 1 m/s along x, the estimate 1.1 m/s: every 1 s
// pair is 0.1 m off. evaluate_rpe.py pairs i with the stamp closest to t_i + 1 s and drops
// pairs ending on the last pose, so only (0 s, 1 s) and (0.5 s, 1.5 s) count.
TEST(TrajectoryMetrics, HandComputedRpeTranslationDrift) {
  Trajectory gt, est;
  for (int k = 0; k < 5; ++k) {
    const double t = 0.5 * k;
    gt.push_back({t, makePose(Eigen::Vector3d(t, 0, 0))});
    est.push_back({t, makePose(Eigen::Vector3d(1.1 * t, 0, 0))});
  }
  const RpeResult r = TrajectoryMetrics::computeRpe(gt, est, 1.0);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_EQ(r.pairs, 2u);
  EXPECT_NEAR(r.translation.rmse, 0.1, 1e-12);
  EXPECT_NEAR(r.translation.mean, 0.1, 1e-12);
  EXPECT_NEAR(r.translation.median, 0.1, 1e-12);
  EXPECT_LT(r.rotationDegrees.max, 1e-5);
}

// Same, plus the estimate yawing 2 deg/s (gt does not rotate). With
// error = (est_j^-1 est_i)^-1 (gt_j^-1 gt_i) the translational error of pair (i, j) is
// |(1.1, 0, 0) - R(theta_j) (1, 0, 0)| with theta_j = 2 deg * t_j; the rotational error is 2 deg.
// (The other composition order would give theta_i instead of theta_j.)
TEST(TrajectoryMetrics, HandComputedRpeRotationDrift) {
  Trajectory gt, est;
  for (int k = 0; k < 5; ++k) {
    const double t = 0.5 * k;
    gt.push_back({t, makePose(Eigen::Vector3d(t, 0, 0))});
    est.push_back(
        {t,
         makePose(Eigen::Vector3d(1.1 * t, 0, 0),
                  Eigen::AngleAxisd(2 * kDeg * t, Eigen::Vector3d::UnitZ()).toRotationMatrix())});
  }
  auto expected = [](double tj) {
    const double th = 2 * kDeg * tj;
    return std::hypot(1.1 - std::cos(th), std::sin(th));
  };
  const double e1 = expected(1.0), e2 = expected(1.5);
  const RpeResult r = TrajectoryMetrics::computeRpe(gt, est, 1.0);
  ASSERT_TRUE(r.valid) << r.reason;
  ASSERT_EQ(r.pairs, 2u);
  EXPECT_NEAR(r.translation.rmse, std::sqrt((e1 * e1 + e2 * e2) / 2), 1e-12);
  EXPECT_NEAR(r.translation.mean, (e1 + e2) / 2, 1e-12);
  EXPECT_NEAR(r.translation.max, e2, 1e-12);
  EXPECT_NEAR(r.rotationDegrees.rmse, 2.0, 1e-6);
  EXPECT_NEAR(r.rotationDegrees.median, 2.0, 1e-6);
}

// A camera that turns by 0.9 of the ground truth's angle about one axis: the rotation scale
// is 0.9 about that axis, whatever the world frame, and undetermined (NaN) about the others.
TEST(TrajectoryMetrics, RotationScaleIsPerCameraAxis) {
  for (int axis = 0; axis < 3; ++axis) {
    Trajectory gt, est;
    for (int k = 0; k < 300; ++k) {
      const double t = k / 30.0;
      const double angle = 0.4 * std::sin(0.7 * t);
      const Eigen::Vector3d pos(0.3 * t, 0.1 * std::sin(t), 0.0);
      const Eigen::Vector3d unit = Eigen::Vector3d::Unit(axis);
      gt.push_back({t, makePose(pos, Eigen::AngleAxisd(angle, unit).toRotationMatrix())});
      est.push_back({t, makePose(pos, Eigen::AngleAxisd(0.9 * angle, unit).toRotationMatrix())});
    }
    const RpeResult r =
        TrajectoryMetrics::computeRpe(gt, transformed(est, someRigidTransform()), 1.0);
    ASSERT_TRUE(r.valid) << r.reason;
    for (int other = 0; other < 3; ++other) {
      if (other == axis)
        EXPECT_NEAR(r.rotationScale[other], 0.9, 1e-9) << "axis " << axis;
      else
        EXPECT_TRUE(std::isnan(r.rotationScale[other])) << "axis " << axis << ", " << other;
    }
  }
}

TEST(TrajectoryMetrics, RpeShorterThanDeltaReportsNotEnoughSpan) {
  const Trajectory gt = syntheticTrajectory(27, 30.0);  // 0.87 s
  const RpeResult r = TrajectoryMetrics::computeRpe(gt, gt, 1.0);
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.pairs, 0u);
  EXPECT_NE(r.reason.find("not enough span"), std::string::npos) << r.reason;
  // ATE still works on such a trajectory; evaluate() reports RPE as unavailable.
  const TrajectoryEvaluation ev = TrajectoryMetrics::evaluate(gt, gt);
  EXPECT_LT(ev.ate.stats.rmse, 1e-12);
  EXPECT_FALSE(ev.rpe.valid);
}

// evaluate_rpe.py accepts a gt stamp up to 2 x the median gt interval away (here 2 x 0.01 s);
// an estimate 0.015 s off the gt stamps is evaluated, one 0.03 s off is not.
TEST(TrajectoryMetrics, RpeGroundTruthWindowIsTwiceMedianInterval) {
  const Trajectory gt = syntheticTrajectory(500, 100.0);
  Trajectory near, far;
  for (std::size_t k = 0; k < gt.size(); k += 10)
    near.push_back({gt[k].timestamp + 0.015, gt[k].pose});
  EXPECT_TRUE(TrajectoryMetrics::computeRpe(gt, near, 1.0).valid);

  // Ground truth every 0.01 s (still the median interval) except for a hole from 0.03 to 0.07 s
  // in every 0.1 s; estimated stamps in the middle of the holes are 0.03 s from any gt stamp.
  Trajectory sparseGt;
  for (const StampedPose& p : gt) {
    const double phase = std::fmod(p.timestamp - gt[0].timestamp + 1e-9, 0.1);
    if (phase > 0.025 && phase < 0.075) continue;
    sparseGt.push_back(p);
  }
  for (std::size_t k = 5; k < gt.size(); k += 10) far.push_back(gt[k]);  // phase 0.05
  const RpeResult r = TrajectoryMetrics::computeRpe(sparseGt, far, 1.0);
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.pairs, 0u);
}

// A camera whose stamps are 10 ms late, against 25 Hz ground truth: the nearest ground-truth
// pose cannot tell an offset finer than its 40 ms spacing, the interpolated ground truth can.
TEST(TrajectoryMetrics, InterpolatedGroundTruthResolvesOffsetsFinerThanItsRate) {
  const Trajectory fine = syntheticTrajectory(10000, 1000.0);  // 1 kHz: the true path
  Trajectory gt, late;
  for (std::size_t k = 0; k + 50 < fine.size(); k += 40) {
    gt.push_back(fine[k]);
    if (k > 0) late.push_back({fine[k].timestamp, fine[k + 10].pose});  // seen 10 ms later
  }
  EvaluationOptions nearest;
  nearest.maxDifference = 0.03;
  nearest.offset = 0.010;
  EvaluationOptions interpolated = nearest;
  interpolated.interpolate = true;
  EvaluationOptions interpolatedNoOffset = interpolated;
  interpolatedNoOffset.offset = 0;

  const double atNearest = TrajectoryMetrics::evaluate(gt, late, nearest).ate.stats.rmse;
  const auto atInterpolated = TrajectoryMetrics::evaluate(gt, late, interpolated);
  const double atNoOffset =
      TrajectoryMetrics::evaluate(gt, late, interpolatedNoOffset).ate.stats.rmse;
  EXPECT_EQ(atInterpolated.pairs, late.size() - 1);  // the last is after the ground truth ends
  EXPECT_LT(atInterpolated.ate.stats.rmse, 2e-4);    // linear interpolation of a smooth path
  EXPECT_GT(atNearest, 1e-3);                        // 10 ms of motion
  EXPECT_GT(atNoOffset, 1e-3);
}

TEST(TrajectoryMetrics, InterpolationSkipsGroundTruthGaps) {
  const Trajectory all = syntheticTrajectory(300, 100.0);  // 3 s at 100 Hz
  Trajectory gt;
  for (const StampedPose& p : all)
    if (p.timestamp < 101.0 || p.timestamp > 101.5) gt.push_back(p);  // a 0.5 s dropout
  Trajectory est;
  for (std::size_t k = 5; k < all.size(); k += 10)
    est.push_back({all[k].timestamp + 0.002, all[k].pose});
  EvaluationOptions options;
  options.interpolate = true;
  const auto ev = TrajectoryMetrics::evaluate(gt, est, options);
  std::size_t inGap = 0;
  for (const StampedPose& p : est) inGap += p.timestamp > 101.0 && p.timestamp < 101.5;
  EXPECT_GT(inGap, 3u);
  EXPECT_EQ(ev.pairs, est.size() - inGap);
  EXPECT_EQ(ev.unmatchedEstimatePoses, inGap);

  const Trajectory later = {{200.0, Pose::Identity()}, {200.1, Pose::Identity()}};
  EXPECT_THROW(TrajectoryMetrics::evaluate(gt, later, options), std::runtime_error);
}
