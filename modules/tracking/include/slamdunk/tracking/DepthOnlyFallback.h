#pragma once
// The tracker's fallback when the features do not register a frame (textureless or dark
// views): the frame's depth alone is aligned with the last reference keyframe's
// (DepthOnlyRegistration.h), from the poses the camera most likely has.

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/tracking/DenseDepthTerm.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <opencv2/core.hpp>

#include <optional>
#include <string>

namespace slamdunk {

class DepthOnlyFallback {
 public:
  DepthOnlyFallback(const TrackerOptions& options, const KeyframeGraph& graph,
                    const DenseDepthTerm& dense);

  /// Whether a frame may be registered by depth alone: only right after a tracked frame (the
  /// prediction must be close for the alignment to converge, and a lost camera is found again
  /// by relocalization), against a reference keyframe still in the map.
  bool possible(bool lost, KeyframeId lastReference) const;

  struct Result {
    bool registered = false;
    Pose pose = Pose::Identity();
    /// Share of the frame's depth samples that land on the keyframe's: the overlap estimate.
    double overlap = 0;
    DepthAlignmentTerm term;  ///< the term aligned with (for the keyframe's depth edge)
    std::string failure;      ///< why not registered
  };
  /// Aligns the frame's depth with keyframe `reference` (at `referencePose` in the world),
  /// starting from the last frame's pose (`lastPose`) moved on by `lastMotion` and from
  /// `lastPose` itself.
  Result registerFrame(const RgbdFrame& frame, KeyframeId reference, const Pose& referencePose,
                       const Pose& lastPose, const std::optional<Pose>& lastMotion);

 private:
  const TrackerOptions& options_;
  const KeyframeGraph& graph_;
  const DenseDepthTerm& dense_;
  /// The reference keyframe's normals, fitted once per keyframe: a dark stretch aligns many
  /// frames with the same one.
  KeyframeId normalsKeyframe_ = 0;
  cv::Mat normals_;
};

}  // namespace slamdunk
