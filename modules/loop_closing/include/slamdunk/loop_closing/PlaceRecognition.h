#pragma once
// Place recognition beyond the active window (issue 46): each new keyframe is described by
// its visual words and looked up in an index over the whole map. The best-scoring keyframes
// far from it in the graph are verified by matching their descriptors and RANSAC on the 3D
// matches; a loop is accepted once consecutive keyframes verify loops that agree with the
// odometry between them. Deterministic: seeded words and RANSAC, candidates in a fixed order.

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/loop_closing/LoopClosingOptions.h>
#include <slamdunk/loop_closing/PlaceIndex.h>

#include <optional>
#include <vector>

namespace slamdunk {

/// A verified loop: keyframe `query` sees what the older keyframe `candidate` saw.
struct LoopHypothesis {
  struct Match {
    uint32_t candidateFeature = 0, queryFeature = 0;
    double ratio = 0;  ///< θ' of the descriptor ratio test
  };
  KeyframeId query = 0, candidate = 0;
  Pose T_candidate_query = Pose::Identity();  ///< measured by RANSAC on the matches
  std::vector<Match> inliers;
  double score = 0;  ///< the index's similarity of the two
  /// The two keyframes were in unconnected components of the map: the loop joins them.
  bool joins = false;
};

class PlaceRecognition {
 public:
  explicit PlaceRecognition(const LoopClosingOptions& options);

  struct Detection {
    std::vector<LoopHypothesis> accepted;  ///< consistent loops of consecutive keyframes
    int candidatesVerified = 0;
    /// Verified by RANSAC, but asking for a correction no odometry drifts into (another place
    /// that looks the same).
    int candidatesRefused = 0;
    /// Joins of two components refused: where the join would put the new component's other
    /// keyframes, the map's keyframes see something else (a repeated structure).
    int joinsRefused = 0;
  };
  /// Keyframe `id`, just added to `graph`: looked up, then indexed. Most keyframes accept
  /// nothing.
  Detection keyframeAdded(const KeyframeGraph& graph, KeyframeId id);
  /// Forgets pending hypotheses (after a correction, which moved the poses they agree with).
  void resetConsistency() { chain_.clear(); }
  const PlaceIndex& index() const { return index_; }

 private:
  void learnWords(const KeyframeGraph& graph);
  std::vector<KeyframeId> candidates(const KeyframeGraph& graph, KeyframeId id,
                                     const BagOfWords& bag) const;
  std::optional<LoopHypothesis> verify(const Keyframe& query, const Keyframe& candidate) const;
  bool agree(const LoopHypothesis& a, const LoopHypothesis& b, const KeyframeGraph& graph) const;
  /// Whether the correction the loop asks for is one odometry could have drifted into.
  bool plausibleDrift(const LoopHypothesis& h, const KeyframeGraph& graph) const;
  /// Whether joining `h`'s components would put keyframes of the new one where the map's
  /// keyframes, seeing from nearly the same pose, do not see the same (no path bounds a join,
  /// so its other keyframes are the evidence).
  bool joinContradicted(const LoopHypothesis& h, const KeyframeGraph& graph) const;

  LoopClosingOptions options_;
  PlaceIndex index_;
  size_t wordsLearnedAt_ = 0;          ///< keyframes in the map when the words were learned
  std::vector<LoopHypothesis> chain_;  ///< agreeing loops of consecutive keyframes
  std::optional<KeyframeId> lastKeyframe_;
};

}  // namespace slamdunk
