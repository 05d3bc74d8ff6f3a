#include <slamdunk/tracking/DenseDepthTerm.h>

namespace slamdunk {

DenseDepthTerm::DenseDepthTerm(const TrackerOptions& options, const KeyframeGraph& graph)
    : options_(options), graph_(graph) {}

std::optional<DepthAlignmentTerm> DenseDepthTerm::against(const RgbdFrame& frame,
                                                          KeyframeId reference) const {
  const KeyframePtr kf = graph_.keyframe(reference);
  if (!kf || kf->depthSmall.empty()) return std::nullopt;
  if (cachedKeyframe_ != reference || cachedDepth_.empty()) {
    cv::Mat depth;
    kf->depthSmall.convertTo(depth, CV_32F);
    cachedKeyframe_ = reference;
    cachedDepth_ = undistortedDepth(depth, kf->intrinsics, kf->depthSmallStride);
  }
  DepthAlignmentTerm term;
  term.referenceDepth = cachedDepth_;
  term.referenceIntrinsics = scaleIntrinsics(kf->intrinsics, kf->depthSmallStride);
  term.weight = options_.depthAlignmentWeight;
  term.maxDistance = options_.depthAlignmentMaxDistance;
  term.centralNormals = options_.depthAlignmentCentralNormals;
  term.framePoints =
      depthSamples(frame, options_.depthAlignmentStride, options_.depthAlignmentMaxDepth);
  return term;
}

}  // namespace slamdunk
