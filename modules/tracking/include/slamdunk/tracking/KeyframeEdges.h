#pragma once
// The graph edges of a new keyframe (paper Sec. 4.2-4.3): its inlier matches with each keyframe
// it was registered against, weighed by the ratio test and the features' depth noise, and
// optionally the depth term's point-to-plane associations with its reference keyframe.

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/tracking/DenseDepthTerm.h>
#include <slamdunk/tracking/FrameRegistrar.h>
#include <slamdunk/tracking/TrackerOptions.h>

namespace slamdunk {

/// One feature match as a graph point match between keyframe `other` (its feature
/// `otherIndex`) and a newer one `fresh` (its feature `freshIndex`), matched with ratio θ':
/// weighed by the ratio test and, per `information`, the features' depth and scale noise.
/// R_other_fresh rotates the newer keyframe's frame into the other's.
PointMatch weighedPointMatch(const FeatureSet& other, uint32_t otherIndex, const FeatureSet& fresh,
                             uint32_t freshIndex, double ratio,
                             const Eigen::Matrix3d& R_other_fresh, const DepthNoiseModel& noise,
                             EdgeInformation information, double keypointScaleSigma);

class KeyframeEdges {
 public:
  /// `noise` is the tracker's, which changes as frames come.
  KeyframeEdges(const TrackerOptions& options, const DepthNoiseModel& noise, KeyframeGraph& graph,
                const DenseDepthTerm& dense);

  /// Edges from keyframe `id` (its `features`) to every keyframe holding at least
  /// edge_min_matches of the registration's inliers; the points as measured, not as refined.
  void linkMatches(KeyframeId id, const FeatureSet& features, const Registration& registration);
  /// Adds the last depth term's point-to-plane associations (at the keyframe's `pose`) to the
  /// edge with its reference keyframe, so the local optimization keeps what the alignment
  /// measured.
  void linkDepth(KeyframeId id, const Pose& pose);

 private:
  const TrackerOptions& options_;
  const DepthNoiseModel& noise_;
  KeyframeGraph& graph_;
  const DenseDepthTerm& dense_;
};

}  // namespace slamdunk
