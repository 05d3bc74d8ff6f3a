#pragma once
// Keyframes that follow the space covered, not the time spent (issue 45). A camera that
// dwells in a room keeps spawning keyframes whenever the overlap dips (blur, a turn), each one
// seeing what others already see. A keyframe is redundant when nearly every feature of it
// that the map matched is matched by enough other keyframes too: it is culled, and its
// neighbours' feature tracks through it are joined directly, so the bundle adjustment keeps
// the points it followed. Frames that referred to it follow its successor (KeyframeGraph).

#include <slamdunk/graph/KeyframeGraph.h>

#include <vector>

namespace slamdunk {

struct KeyframeCullingOptions {
  /// A keyframe is culled when at least this share of its matched features is matched by
  /// `minObservers` other keyframes. 0: off (the paper keeps every keyframe).
  double redundantShare = 0;
  int minObservers = 2;
};

class KeyframeCulling {
 public:
  struct Verdict {
    size_t matchedFeatures = 0;  ///< its features matched by at least one other keyframe
    size_t coveredFeatures = 0;  ///< ... by at least minObservers other keyframes
    double coveredShare() const {
      return matchedFeatures == 0 ? 0.0 : double(coveredFeatures) / double(matchedFeatures);
    }
    KeyframeId successor = 0;  ///< the neighbour sharing most matches with it
    /// Matches joining, feature by feature, the other keyframes that matched it (i < j). The
    /// landmark bundle adjustment (the default) weighs landmarks, not these matches' weights;
    /// the pairwise forms give them the paper's weight 1.
    std::vector<KeyframeEdge> rewired;
  };
  explicit KeyframeCulling(KeyframeCullingOptions options = {}) : options_(options) {}

  /// How much of keyframe `id` other keyframes see (from the graph's edges).
  Verdict examine(const KeyframeGraph& graph, KeyframeId id) const;

  /// Culls the redundant keyframes among `candidates`, examined in order (each against the
  /// graph the previous culls left). Returns the ids culled.
  std::vector<KeyframeId> cull(KeyframeGraph& graph,
                               const std::vector<KeyframeId>& candidates) const;

  const KeyframeCullingOptions& options() const { return options_; }

 private:
  KeyframeCullingOptions options_;
};

}  // namespace slamdunk
