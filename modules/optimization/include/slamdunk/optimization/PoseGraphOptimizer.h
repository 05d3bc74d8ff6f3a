#pragma once
// Pose-graph optimization over the whole keyframe graph, the first step of a loop correction:
// every edge keeps the relative pose its keyframes have now, the loops add the relative poses
// they measured, and the loops' error spreads along the graph. Cheap (poses only, no points),
// so it goes first; the relative bundle adjustment around the loop's ends then refines.
// Ceres is an implementation detail: this header does not include it.

#include <slamdunk/core/Pose.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <string>
#include <vector>

namespace slamdunk {

/// A measured relative pose between two keyframes: T_i_j maps j's frame into i's.
struct RelativePoseConstraint {
  KeyframeId i = 0, j = 0;
  Pose T_i_j = Pose::Identity();
};

struct PoseGraphOptions {
  /// Standard deviations of every constraint, the graph's edges and the loops alike: only
  /// their ratio matters, and it says how a loop's error is shared between translation and
  /// rotation.
  double translationSigma = 0.01;  ///< metres
  double rotationSigma = 0.01;     ///< radians
  int maxIterations = 50;
};

struct PoseGraphReport {
  bool usable = false;  ///< poses were written back
  size_t vertices = 0, constraints = 0;
  int iterations = 0;
  double initialCost = 0, finalCost = 0;
  double timeMs = 0;
  double maxTranslationChange = 0;  ///< metres, largest over the keyframes moved
  std::string message;
};

/// Optimizes the poses of every keyframe of the graph, the oldest of each connected component
/// (after adding the loops) held fixed, and writes them back at once; keyframes added while it
/// ran, or caught in the snapshot before their edges, move with the newest it optimized
/// (KeyframeGraph::applyCorrection).
PoseGraphReport optimizePoseGraph(KeyframeGraph& graph,
                                  const std::vector<RelativePoseConstraint>& loops,
                                  const PoseGraphOptions& options = {});

}  // namespace slamdunk
