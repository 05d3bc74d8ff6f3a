#pragma once
// The dense depth term (DepthAlignmentTerm) of a frame against a keyframe's depth: the feature
// registration refines with it, the depth-only fallback aligns with it alone, and a new
// keyframe's depth edge keeps the associations of the last one used.

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/tracking/PoseRefinement.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <opencv2/core.hpp>

#include <optional>

namespace slamdunk {

class DenseDepthTerm {
 public:
  DenseDepthTerm(const TrackerOptions& options, const KeyframeGraph& graph);

  /// The frame's depth samples against keyframe `reference`'s depth, with the INI's weight and
  /// gates; none if the keyframe has no depth. Its worldFromReference is left to the caller,
  /// who reads the keyframe's pose once per frame.
  std::optional<DepthAlignmentTerm> against(const RgbdFrame& frame, KeyframeId reference) const;

  /// The term the last registration used (refined with, or aligned by depth alone), and its
  /// keyframe: a new keyframe's depth edge keeps its associations.
  struct Last {
    std::optional<DepthAlignmentTerm> term;
    KeyframeId reference = 0;
  };
  Last last;

 private:
  const TrackerOptions& options_;
  const KeyframeGraph& graph_;
  /// One keyframe's depth as float with the lens distortion taken out, once per keyframe:
  /// frame after frame meets the same reference (a cache: against() stays const).
  mutable KeyframeId cachedKeyframe_ = 0;
  mutable cv::Mat cachedDepth_;
};

}  // namespace slamdunk
