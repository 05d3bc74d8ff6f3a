#pragma once
// One inlier of a registered frame, as the estimators of the camera's properties
// (KeypointNoiseEstimator, RollingShutterEstimator) read it.

#include <Eigen/Core>

namespace slamdunk {

struct InlierSample {
  Eigen::Vector3d framePoint;  ///< the feature's point in the frame's optical frame
  Eigen::Vector3d mapPoint;    ///< its match in the world (the map's point)
  double mapDepth = 0;         ///< the map point's depth in the keyframe that measured it
  /// The keypoint's row as a fraction of the image height from its middle (-0.5 top, 0.5
  /// bottom): when a rolling shutter exposed it, relative to the frame's time.
  double rowFraction = 0;
};

}  // namespace slamdunk
