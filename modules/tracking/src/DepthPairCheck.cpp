#include <slamdunk/core/Statistics.h>
#include <slamdunk/tracking/DepthPairCheck.h>

#include <algorithm>
#include <cmath>

namespace slamdunk {

namespace {

/// Median |point-to-plane distance| of the term's associations at pose T (0 when none).
double medianResidual(const Pose& T, const DepthAlignmentTerm& term) {
  std::vector<double> r;
  for (const DepthCorrespondence& c : depthCorrespondences(T, term))
    r.push_back(std::abs(c.residual));
  return r.empty() ? 0 : upperMedian(std::move(r));
}

}  // namespace

DepthPairCheck checkDepthPair(const RgbdFrame& source, const RgbdFrame& target,
                              const Pose& targetFromSource, const DepthPairCheckOptions& options) {
  DepthPairCheck out;
  out.given = out.alignedPose = targetFromSource;
  DepthAlignmentTerm term;
  term.framePoints = depthSamples(source, options.stride, options.maxDepth);
  term.referenceDepth = undistortedDepth(target.depth(), target.intrinsics(), 1);
  term.referenceIntrinsics = scaleIntrinsics(target.intrinsics(), 1);
  term.referenceNormals = fitPlaneNormals(term.referenceDepth, term.referenceIntrinsics,
                                          options.alignment.normalRadius);
  term.maxDistance = options.alignment.maxDistances.back();
  out.medianResidualGiven = medianResidual(targetFromSource, term);

  const DepthOnlyResult r = registerByDepthOnly(targetFromSource, term, options.alignment);
  out.aligned = r.success;
  out.failure = r.failure;
  out.alignedPose = r.pose;
  out.medianResidualAligned = medianResidual(r.pose, term);
  return out;
}

}  // namespace slamdunk
