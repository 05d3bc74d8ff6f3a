#pragma once
// Whether the map already shows what a frame shows. The overlap test (KeyframePolicy) counts
// the frame's cells that hold matched inliers; a blurred or badly lit frame matches little even
// where keyframes show the same surfaces from the same place, and a keyframe made of it adds
// nothing but a worse copy of the view. This measures the view itself: the share of the frame's
// 3D points that a keyframe sees from nearly the same direction and distance (where its
// features would match them), in its image and not hidden behind its depth.

#include <slamdunk/graph/KeyframeGraph.h>

#include <vector>

namespace slamdunk {

struct ViewCoverageOptions {
  /// A keyframe sees a point as the frame does when its ray to the point is within this angle
  /// of the frame's (degrees) ...
  double maxViewAngleDeg = 15;
  /// ... and its distance to the point within this factor of the frame's (either way).
  double maxDistanceRatio = 1.25;
};

class ViewCoverage {
 public:
  explicit ViewCoverage(ViewCoverageOptions options = {}) : options_(options) {}

  /// Share of `points` (the frame's feature points in its optical frame, at pose `frame`) that
  /// at least one of `keyframes` sees as the frame does (0 when there are no points).
  double coveredShare(const std::vector<Eigen::Vector3d>& points, const Pose& frame,
                      const KeyframeGraph& graph, const std::vector<KeyframeId>& keyframes) const;

 private:
  ViewCoverageOptions options_;
};

}  // namespace slamdunk
