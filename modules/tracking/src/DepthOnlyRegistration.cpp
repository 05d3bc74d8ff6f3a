#include <slamdunk/tracking/DepthOnlyRegistration.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace slamdunk {

namespace {

/// Share of the associated surfaces that face the geometry's weakest direction (within 60°).
/// That direction is the least-spread eigenvector of the normals' scatter: along the line
/// where a wall meets the floor, say, nothing holds the pose. Counting surfaces rather than
/// using the eigenvalue keeps the normals' remaining noise from passing for a constraint.
double weakestConstraint(const std::vector<DepthCorrespondence>& c) {
  if (c.size() < 6) return 0;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const DepthCorrespondence& x : c) scatter += x.normal * x.normal.transpose();
  const Eigen::Vector3d weakest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  const auto facing = std::count_if(c.begin(), c.end(), [&](const DepthCorrespondence& x) {
    return std::abs(x.normal.dot(weakest)) > 0.5;
  });
  return static_cast<double>(facing) / static_cast<double>(c.size());
}

std::string describe(const char* what, double value, const char* op, double bound) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "depth-only: %s %.3g (%s %.3g)", what, value, op, bound);
  return buf;
}

}  // namespace

DepthOnlyResult registerByDepthOnly(const Pose& predicted, DepthAlignmentTerm term,
                                    const DepthOnlyOptions& options) {
  DepthOnlyResult r;
  r.pose = predicted;
  if (term.framePoints.empty() || term.referenceDepth.empty()) {
    r.failure = "depth-only: no depth to align";
    return r;
  }
  if (term.referenceNormals.empty())
    term.referenceNormals =
        fitPlaneNormals(term.referenceDepth, term.referenceIntrinsics, options.normalRadius);
  PoseRefinementOptions refinement;
  refinement.iterations = options.iterationsPerLevel;
  for (double gate : options.maxDistances) {
    term.maxDistance = gate;
    r.pose = refinePose(r.pose, {}, refinement, &term);
  }
  if (!r.pose.matrix().allFinite()) {
    r.failure = "depth-only: the alignment diverged";
    return r;
  }
  // Re-orthonormalised: a constant-velocity prediction composes this pose with itself frame
  // after frame, which amplifies rounding errors in the rotation (x2.4 per frame, measured).
  r.pose.linear() = Eigen::Quaterniond(r.pose.linear()).normalized().toRotationMatrix();

  const std::vector<DepthCorrespondence> c = depthCorrespondences(r.pose, term);
  r.associatedFraction = depthOverlap(r.pose, term);
  double sq = 0;
  for (const DepthCorrespondence& x : c) sq += x.residual * x.residual;
  r.rmsResidual = c.empty() ? 0 : std::sqrt(sq / c.size());
  r.constraint = weakestConstraint(c);

  if (r.associatedFraction < options.minAssociatedFraction)
    r.failure = describe("overlap", r.associatedFraction, "<", options.minAssociatedFraction);
  else if (r.rmsResidual > options.maxRmsResidual)
    r.failure = describe("residual", r.rmsResidual, ">", options.maxRmsResidual);
  else if (r.constraint < options.minConstraint)
    r.failure = describe("weakest direction", r.constraint, "<", options.minConstraint);
  else
    r.success = true;
  return r;
}

}  // namespace slamdunk
