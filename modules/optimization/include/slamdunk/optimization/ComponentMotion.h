#pragma once
// One rigid motion of a whole part of the map, fitted to point matches between its keyframes
// and keyframes that stay: how a join places the newer component on the older (issue 46).
// Fitted to every join loop's matches at once, each weighed by its noise, rather than to one
// loop's relative pose: a loop's rotation is good to a tenth of a degree, and the lever arm of
// the metres the component mapped alone makes that centimetres.

#include <slamdunk/core/Pose.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <optional>
#include <vector>

namespace slamdunk {

/// The matches of one loop between a keyframe that stays and one that moves with its part.
struct AnchoredMatches {
  Pose fixedPose = Pose::Identity();   ///< world ← the keyframe that stays
  Pose movingPose = Pose::Identity();  ///< world ← the keyframe that moves, before the move
  /// pointI in the staying keyframe's frame, pointJ in the moving one's; information in the
  /// staying one's frame (PointMatch's convention with i the staying keyframe).
  std::vector<PointMatch> matches;
};

/// The motion M (moved poses are M T) minimising Σ w eᵀ Ω e over all matches, from `initial`;
/// empty when the matches do not determine it (fewer than three) or the solver fails.
std::optional<Pose> fitRigidMotion(const std::vector<AnchoredMatches>& loops, const Pose& initial);

}  // namespace slamdunk
