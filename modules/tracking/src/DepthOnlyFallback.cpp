#include <slamdunk/tracking/DepthOnlyFallback.h>
#include <slamdunk/tracking/DepthOnlyRegistration.h>

#include <vector>

namespace slamdunk {

DepthOnlyFallback::DepthOnlyFallback(const TrackerOptions& options, const KeyframeGraph& graph,
                                     const DenseDepthTerm& dense)
    : options_(options), graph_(graph), dense_(dense) {}

bool DepthOnlyFallback::possible(bool lost, KeyframeId lastReference) const {
  return options_.depthOnlyFallback && options_.depthAlignmentStride > 0 && !lost &&
         graph_.contains(lastReference);
}

DepthOnlyFallback::Result DepthOnlyFallback::registerFrame(const RgbdFrame& frame,
                                                           KeyframeId reference,
                                                           const Pose& referencePose,
                                                           const Pose& lastPose,
                                                           const std::optional<Pose>& lastMotion) {
  Result result;
  std::optional<DepthAlignmentTerm> term = dense_.against(frame, reference);
  if (!term) {
    result.failure = "depth-only: the reference keyframe has no depth";
    return result;
  }
  term->worldFromReference = referencePose;
  term->weight = 1.0;  // alone: its scale does not matter, but 0 (dense term off) would
  if (normalsKeyframe_ != reference || normals_.empty()) {
    normals_ = fitPlaneNormals(term->referenceDepth, term->referenceIntrinsics,
                               options_.depthOnly.normalRadius);
    normalsKeyframe_ = reference;
  }
  term->referenceNormals = normals_;
  // Two predictions, constant velocity (a camera circling an object) and standing still; the
  // accepted alignment that explains more of the frame wins.
  std::vector<Pose> predictions{lastPose};
  if (lastMotion) predictions.insert(predictions.begin(), lastPose * *lastMotion);
  std::optional<DepthOnlyResult> best;
  std::string failure;
  for (const Pose& predicted : predictions) {
    DepthOnlyResult c = registerByDepthOnly(predicted, *term, options_.depthOnly);
    if (!c.success) {
      if (failure.empty()) failure = c.failure;
    } else if (!best || c.associatedFraction > best->associatedFraction) {
      best = std::move(c);
    }
  }
  if (!best) {
    result.failure = failure;
    return result;
  }
  if (options_.maxTranslationJump > 0 &&
      translationDistance(best->pose, lastPose) > options_.maxTranslationJump) {
    result.failure = "depth-only: implausible jump of " +
                     std::to_string(translationDistance(best->pose, lastPose)) + " m";
    return result;
  }
  term->maxDistance = options_.depthAlignmentMaxDistance;
  result.registered = true;
  result.pose = best->pose;
  result.overlap = best->associatedFraction;
  result.term = std::move(*term);
  return result;
}

}  // namespace slamdunk
