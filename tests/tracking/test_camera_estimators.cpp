// What the tracker learns of its camera from the registered frames: the features' noise
// (KeypointNoiseEstimator) and the colour camera's rolling-shutter readout
// (RollingShutterEstimator). Frames are simulated with known values; the estimators must find
// them, and must not invent a readout for a global shutter or a camera that does not move.
#include <slamdunk/tracking/KeypointNoiseEstimator.h>
#include <slamdunk/tracking/RollingShutterEstimator.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

using namespace slamdunk;

namespace {

/// Points in front of a camera at `pose`, as a registered frame's inliers: the frame's point
/// (measured now, with pixel and depth noise, and bent by a rolling shutter of `readoutMs` while
/// the camera moves by `motion` every `intervalMs`) and the map's point (measured from a nearby
/// keyframe with the same noise).
std::vector<InlierSample> simulateFrame(std::mt19937& rng, const Pose& pose,
                                        const DepthNoiseModel& noise, const Pose& motion,
                                        double intervalMs, double readoutMs, int count = 300) {
  std::uniform_real_distribution<double> ux(-0.45, 0.45), uy(-0.35, 0.35), uz(0.8, 3.0);
  std::normal_distribution<double> g(0, 1);
  const Eigen::AngleAxisd rotation(motion.linear());
  const Eigen::Vector3d omega = rotation.angle() * rotation.axis() / intervalMs;
  const Eigen::Vector3d velocity = motion.translation() / intervalMs;
  auto measure = [&](const Eigen::Vector3d& p) {
    const double f = noise.focalLength;
    const double u = f * p.x() / p.z() + noise.pixelSigma * g(rng);
    const double v = f * p.y() / p.z() + noise.pixelSigma * g(rng);
    const double z = p.z() + noise.depthSigma(p.z()) * g(rng);
    return Eigen::Vector3d(u / f * z, v / f * z, z);
  };
  std::vector<InlierSample> out;
  for (int n = 0; n < count; ++n) {
    const double z = uz(rng);
    const Eigen::Vector3d p(ux(rng) * z, uy(rng) * z, z);  // in the frame's camera
    const double rowFraction = p.y() / p.z() * noise.focalLength / 480.0;
    // The row exposed τ = rowFraction·readout after the frame's time sees the point where the
    // moved camera has it: p − τ (ω × p + v) to first order.
    const double tau = rowFraction * readoutMs;
    const Eigen::Vector3d seen = p - tau * (omega.cross(p) + velocity);
    InlierSample s;
    s.framePoint = measure(seen);
    // The map point, measured by a keyframe at about the same place.
    s.mapPoint = pose * measure(p);
    s.mapDepth = p.z();
    s.rowFraction = rowFraction;
    out.push_back(s);
  }
  return out;
}

Pose motionOf(double degrees, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  Pose m = Pose::Identity();
  m.linear() = Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()).toRotationMatrix();
  m.translation() = translation;
  return m;
}

}  // namespace

TEST(KeypointNoiseEstimator, FindsThePixelAndDepthNoiseOfTheFrames) {
  for (const auto& [pixel, depth] : {std::pair{0.2, 0.0003}, {0.7, 0.004}, {1.5, 0.012}}) {
    DepthNoiseModel truth;
    truth.pixelSigma = pixel;
    truth.depthSigmaQuadratic = depth;
    DepthNoiseModel prior;  // the INI's defaults
    KeypointNoiseEstimator estimator(prior, {});
    std::mt19937 rng(1);
    for (int frame = 0; frame < 40; ++frame)
      estimator.addFrame(simulateFrame(rng, Pose::Identity(), truth, Pose::Identity(), 33, 0),
                         Pose::Identity());
    const DepthNoiseModel& found = estimator.current();
    std::cout << "truth " << pixel << " px, " << depth << " m: found " << found.pixelSigma
              << " px, " << found.depthSigmaQuadratic << " m\n";
    EXPECT_NEAR(found.pixelSigma, pixel, 0.15 * pixel);
    EXPECT_NEAR(found.depthSigmaQuadratic, depth, 0.2 * depth);
  }
}

TEST(KeypointNoiseEstimator, KeepsThePriorUntilEnoughFramesAndWhenDisabled) {
  DepthNoiseModel truth;
  truth.pixelSigma = 2.0;
  DepthNoiseModel prior;
  KeypointNoiseEstimatorOptions o;
  KeypointNoiseEstimator estimator(prior, o);
  o.enabled = false;
  KeypointNoiseEstimator disabled(prior, o);
  std::mt19937 rng(2);
  for (int frame = 0; frame < o.minFrames - 1; ++frame) {
    const auto f = simulateFrame(rng, Pose::Identity(), truth, Pose::Identity(), 33, 0);
    estimator.addFrame(f, Pose::Identity());
    disabled.addFrame(f, Pose::Identity());
  }
  EXPECT_EQ(estimator.current().pixelSigma, prior.pixelSigma);
  // Too few inliers: not a measurement.
  estimator.addFrame(simulateFrame(rng, Pose::Identity(), truth, Pose::Identity(), 33, 0, 5),
                     Pose::Identity());
  EXPECT_EQ(estimator.current().pixelSigma, prior.pixelSigma);
  const auto f = simulateFrame(rng, Pose::Identity(), truth, Pose::Identity(), 33, 0);
  estimator.addFrame(f, Pose::Identity());
  disabled.addFrame(f, Pose::Identity());
  EXPECT_NEAR(estimator.current().pixelSigma, 2.0, 0.3);
  EXPECT_EQ(disabled.current().pixelSigma, prior.pixelSigma);
}

TEST(RollingShutterEstimator, FindsTheReadoutOfAMovingCamera) {
  DepthNoiseModel noise;
  noise.pixelSigma = 0.7;
  noise.depthSigmaQuadratic = 0.004;
  for (double readout : {0.0, 12.0, 26.0}) {
    RollingShutterEstimator estimator(0, {});
    std::mt19937 rng(3);
    Pose pose = Pose::Identity();
    for (int frame = 0; frame < 150; ++frame) {
      // A hand: turning up to 60 deg/s and moving up to 0.4 m/s, changing direction.
      const double phase = 0.2 * frame;
      const Pose motion =
          motionOf(2.0 * std::sin(phase), Eigen::Vector3d(std::cos(phase), 1, 0.3),
                   0.013 * Eigen::Vector3d(std::cos(0.7 * phase), std::sin(phase), 0.3));
      pose = pose * motion;
      // Frames corrected with the readout in use, as the tracker does: the residual left is
      // what the estimate still misses.
      const double applied = estimator.readoutMs();
      auto inliers = simulateFrame(rng, pose, noise, motion, 33, readout - applied);
      estimator.addFrame(inliers, pose, motion, 33, noise, applied);
    }
    std::cout << "readout " << readout << " ms: found " << estimator.readoutMs() << " ms (σ "
              << estimator.sigmaMs() << ")\n";
    EXPECT_NEAR(estimator.readoutMs(), readout, 1.5);
  }
}

TEST(RollingShutterEstimator, AStillCameraTellsNothing) {
  DepthNoiseModel noise;
  RollingShutterEstimator estimator(7.0, {});
  std::mt19937 rng(4);
  for (int frame = 0; frame < 100; ++frame)
    estimator.addFrame(simulateFrame(rng, Pose::Identity(), noise, Pose::Identity(), 33, 0),
                       Pose::Identity(), Pose::Identity(), 33, noise, 7.0);
  EXPECT_EQ(estimator.readoutMs(), 7.0);  // the initial value: no evidence either way
}
