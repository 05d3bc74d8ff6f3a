#pragma once
// Pairs the poses of two trajectories by timestamp, exactly as the TUM RGB-D benchmark's
// associate.py does (used by evaluate_ate.py).

#include <slamdunk/core/TumTrajectory.h>

#include <cstddef>
#include <vector>

namespace slamdunk::eval {

/// Indices into the ground-truth and estimated trajectories of one associated pair.
struct AssociatedPair {
  std::size_t gt = 0;
  std::size_t est = 0;
};

struct TrajectoryAssociation {
  /// One-to-one pairs, sorted by ground-truth stamp (then estimate stamp).
  std::vector<AssociatedPair> pairs;
  /// Estimated poses that got no ground-truth partner.
  std::size_t unmatchedEstimates = 0;

  /// associate.py: every (gt stamp a, est stamp b) with |a - (b + offset)| < maxDifference is a
  /// candidate; candidates are taken greedily by increasing |a - (b + offset)| (ties by a, then
  /// b, as Python's tuple sort does) when neither stamp is taken yet.
  /// Works on unsorted input; the result refers to positions in `gt` and `est`.
  static TrajectoryAssociation compute(const Trajectory& gt, const Trajectory& est,
                                       double maxDifference = 0.02, double offset = 0.0);
};

/// Ground truth at the given stamps: each pose interpolated between the two poses of `sortedGt`
/// (sorted by stamp) around its stamp, position linearly and rotation by slerp, when those two
/// are at most `maxGap` seconds apart (a stamp equal to a pose's takes that pose). Stamps with no
/// such pair (outside the ground truth, in a gap) are left out. For comparing time offsets finer
/// than the ground truth's rate, which the nearest pose cannot resolve.
Trajectory interpolatedAt(const Trajectory& sortedGt, const std::vector<double>& stamps,
                          double maxGap);

/// The TUM scripts load trajectories into a dictionary keyed by stamp: sorted by stamp, and for a
/// repeated stamp the last line wins. Returns that view of `traj`; `duplicatesDropped` (optional)
/// receives how many lines were overridden.
Trajectory sortedUniqueByStamp(const Trajectory& traj, std::size_t* duplicatesDropped = nullptr);

}  // namespace slamdunk::eval
