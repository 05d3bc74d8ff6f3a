#pragma once
// A self-contained copy of the part of the graph to optimise, so that the solve runs without
// holding the graph's lock. Building it: snapshot (rings or whole graph), clean the matches,
// then fix the gauge.

#include <slamdunk/graph/KeyframeGraph.h>

#include <map>
#include <set>
#include <vector>

namespace slamdunk {

struct LocalProblem {
  std::map<KeyframeId, Pose> poses;  ///< every vertex touched by an edge (initial values)
  std::set<KeyframeId> fixed;        ///< constant vertices (subset of poses' keys)
  std::vector<KeyframeEdge> edges;   ///< only edges with at least one free endpoint
  /// Focal lengths (fx, fy) of the keyframes, for the landmark form's pixel residuals.
  std::map<KeyframeId, Eigen::Vector2d> focalLengths;
  int invalidMatches = 0;  ///< non-finite point/weight or negative weight
  int droppedMatches = 0;  ///< weight zero or below the minimum

  size_t matchCount() const;
  bool isFree(KeyframeId id) const { return poses.count(id) && !fixed.count(id); }
};

/// Rings 0..R-1 from root free, ring R fixed; edges with both ends in rings 0..R.
LocalProblem snapshotRings(const KeyframeGraph& graph, KeyframeId root, int rings);
/// Every edge of the graph, every vertex free.
LocalProblem snapshotAll(const KeyframeGraph& graph);

/// Drops unusable matches (counting them), then edges left empty or joining two fixed vertices,
/// and keeps in `poses` only the vertices still touched by an edge.
void cleanMatches(LocalProblem& problem, double minWeight);

/// Every connected component without a fixed vertex gets one: `preferred` if it is in that
/// component, else its smallest id. With the rings snapshot this is the paper's rule (the
/// root is fixed when ring R is empty); it also covers components split off by cleaning.
void fixGauge(LocalProblem& problem, const KeyframeId* preferred);

}  // namespace slamdunk
