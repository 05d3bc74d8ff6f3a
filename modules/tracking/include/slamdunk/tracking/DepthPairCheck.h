#pragma once
// Does a trajectory agree with the depth images it was recorded with? For two frames some way
// apart, the trajectory's relative pose is compared with the one that aligns the two depth
// images point-to-plane, started from it. A ground truth (or an estimate) that turns further
// than its own depth images shows it here, independently of the colour camera and its focal
// length: the depth alignment is held mostly by the surfaces' normals, which a focal length
// error hardly changes.

#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/tracking/DepthOnlyRegistration.h>

#include <string>

namespace slamdunk {

struct DepthPairCheckOptions {
  int stride = 4;         ///< pixels between the source frame's depth samples
  double maxDepth = 4.0;  ///< metres: farther depth is too noisy to align
  /// Gates (metres) and iterations of the alignment. Narrow: it starts from a trajectory that
  /// is close, and a wide gate would pull in other surfaces.
  DepthOnlyOptions alignment = {{0.05, 0.03}, 20, 0.3, 0.03, 0.01, 2};
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
