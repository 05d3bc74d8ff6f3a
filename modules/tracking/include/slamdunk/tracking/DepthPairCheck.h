#pragma once
// Does a trajectory agree with the depth images it was recorded with? For two frames some way
// apart, the trajectory's relative pose is compared with the one that aligns the two depth
// images point-to-plane, started from it: a second opinion that does not go through the colour
// camera and its focal length. It is only as good as the depth: exact depth confirms a ground
// truth to 1e-4, but a real Kinect's depth, aligned alone, turns up to a tenth short of motion
// capture about some axis (TUM fr1, README Calibration), so it cannot referee differences of
// that size.

#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/tracking/DepthOnlyRegistration.h>

#include <string>

namespace slamdunk {

struct DepthPairCheckOptions {
  int stride = 4;         ///< pixels between the source frame's depth samples
  double maxDepth = 4.0;  ///< metres: farther depth is too noisy to align
  DepthOnlyOptions alignment;

  DepthPairCheckOptions() {
    // Narrow gates: the alignment starts from a trajectory that is close, and a wide gate would
    // pull in other surfaces. Checks laxer than tracking's fallback: a pair a second apart
    // overlaps less, and a real sensor's residual over a whole view is larger.
    alignment.maxDistances = {0.05, 0.03};
    alignment.iterationsPerLevel = 20;
    alignment.minAssociatedFraction = 0.3;
    alignment.maxRmsResidual = 0.03;
  }
};

struct DepthPairCheck {
  bool aligned = false;            ///< false: the depth alignment was not accepted (see `failure`)
  std::string failure;             ///< why not
  Pose given;                      ///< target <- source, from the trajectory
  Pose alignedPose;                ///< target <- source, after the depth alignment
  double medianResidualGiven = 0;  ///< metres, |point-to-plane| at `given`
  double medianResidualAligned = 0;  ///< metres, |point-to-plane| at `alignedPose`
};

/// Aligns `source`'s depth with `target`'s, starting from `targetFromSource`.
DepthPairCheck checkDepthPair(const RgbdFrame& source, const RgbdFrame& target,
                              const Pose& targetFromSource,
                              const DepthPairCheckOptions& options = {});

}  // namespace slamdunk
