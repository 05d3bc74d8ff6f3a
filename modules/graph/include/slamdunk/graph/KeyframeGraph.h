#pragma once
// The map: keyframe poses (vertices) and the feature matches between keyframes (edges).
// Thread-safe: the tracker reads poses while the local optimizer writes them.

#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/graph/Keyframe.h>

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <shared_mutex>
#include <vector>

namespace slamdunk {

/// A symmetric 3×3 matrix kept as its lower triangle: 6 doubles instead of 9, a sixth of a
/// point match. Read as an Eigen matrix (the upper triangle mirrors the lower); set from any
/// 3×3 Eigen expression, whose upper triangle is then ignored (Cholesky reads only the lower).
class SymmetricMatrix3 {
 public:
  SymmetricMatrix3() : SymmetricMatrix3(Eigen::Matrix3d::Identity()) {}
  template <class Derived>
  SymmetricMatrix3(const Eigen::MatrixBase<Derived>& m) {  // NOLINT: converts like a matrix
    for (int r = 0, k = 0; r < 3; ++r)
      for (int c = 0; c <= r; ++c) lower_[k++] = m(r, c);
  }
  Eigen::Matrix3d matrix() const {
    Eigen::Matrix3d m;
    for (int r = 0, k = 0; r < 3; ++r)
      for (int c = 0; c <= r; ++c) m(r, c) = m(c, r) = lower_[k++];
    return m;
  }
  operator Eigen::Matrix3d() const { return matrix(); }  // NOLINT
  double operator()(int r, int c) const {
    return r >= c ? lower_[lowerIndex(r, c)] : lower_[lowerIndex(c, r)];
  }

 private:
  static int lowerIndex(int r, int c) { return r * (r + 1) / 2 + c; }
  double lower_[6];
};

/// One feature match between two keyframes, as 3D points in each keyframe's own frame.
/// Its cost is weight · eᵀ Ω e with e = p_i − T_i⁻¹ T_j p_j (paper Eq. 4-5 when Ω = I).
struct PointMatch {
  Eigen::Vector3d pointI;  ///< in keyframe i's optical frame
  Eigen::Vector3d pointJ;  ///< in keyframe j's optical frame
  double weight = 1.0;     ///< 1 - θ' (paper Sec. 4.3)
  /// Normalised information of e in keyframe i's frame (symmetric positive definite). The
  /// identity is the paper's isotropic cost; a depth-noise model makes it ray-aligned.
  SymmetricMatrix3 information{};
  /// The matched features' indices in keyframe i's and j's FeatureSet, when the match joins two
  /// features (a bundle adjustment then follows each feature through the keyframes that saw
  /// it); kNoFeature for matches of dense depth.
  static constexpr uint32_t kNoFeature = UINT32_MAX;
  uint32_t featureI = kNoFeature;
  uint32_t featureJ = kNoFeature;
  bool joinsFeatures() const { return featureI != kNoFeature && featureJ != kNoFeature; }

  /// eᵀ Ω e for a relative pose T_i⁻¹ T_j (without the weight).
  double squaredError(const Eigen::Isometry3d& relative) const {
    const Eigen::Vector3d e = pointI - relative * pointJ;
    return e.dot(information.matrix() * e);
  }
};

/// Edge between keyframes i < j carrying their matches (paper Eq. 4-5).
struct KeyframeEdge {
  KeyframeId i = 0, j = 0;
  std::vector<PointMatch> matches;
};

/// Bytes the graph's data takes, counted from the containers (what an allocator adds, and the
/// feature pool, whose size follows the window, are not in it).
struct GraphMemory {
  size_t keyframes = 0;
  size_t features = 0;    ///< keypoints, descriptors and 3D points (measured and refined)
  size_t depthSmall = 0;  ///< the subsampled depth of the dense alignment
  size_t images = 0;      ///< colour and depth, when kept
  size_t edges = 0;       ///< point matches and the edge records
  size_t withoutImages() const { return features + depthSmall + edges; }
  size_t total() const { return withoutImages() + images; }
};

/// Positions of a keyframe's features refined by a landmark bundle adjustment, in the
/// keyframe's frame, one per feature (as measured where no landmark refined it). Immutable once
/// published: a new vector replaces it.
using RefinedPoints = std::shared_ptr<const std::vector<Eigen::Vector3d>>;
/// Refined positions of some features, per keyframe: (feature index, point in its frame).
using PointRefinements = std::map<KeyframeId, std::vector<std::pair<uint32_t, Eigen::Vector3d>>>;

class KeyframeGraph {
 public:
  /// Adds a keyframe with its world pose (optical frame). Ids must be new.
  void addKeyframe(KeyframePtr keyframe, const Pose& T_world_keyframe);
  /// Adds matches between two keyframes; appends if the edge exists. Points are stored with
  /// the smaller id as i.
  void addMatches(KeyframeId a, KeyframeId b, const std::vector<PointMatch>& matchesAB);
  /// Removes a keyframe other keyframes make redundant, with its edges, and adds `rewired` (the
  /// matches that keep its neighbours' feature tracks joined) at once. Frames that referred to
  /// it refer to `successor` from now on: pose(id) follows the successor's pose at the
  /// relative pose the two have now.
  void cullKeyframe(KeyframeId id, KeyframeId successor, const std::vector<KeyframeEdge>& rewired);

  /// Keeps the keyframe's float descriptors as `storage` from now on (CompactDescriptors.h):
  /// half floats, or 8-bit codes for a keyframe far from the active window. A copy replaces
  /// the keyframe: whoever holds it keeps what they have. False if there was nothing to compact
  /// (an unknown id, binary descriptors, or descriptors already that compact or more).
  bool compactDescriptors(KeyframeId id, DescriptorStorage storage = DescriptorStorage::Codes);
  size_t keyframeCount() const;
  size_t edgeCount() const;
  bool contains(KeyframeId id) const;
  /// The keyframe, or null if it is not (or no longer) in the graph.
  KeyframePtr keyframe(KeyframeId id) const;
  /// World pose of a keyframe, or of a culled keyframe through its successor.
  Pose pose(KeyframeId id) const;
  /// The same, or nothing for an id the graph never had.
  std::optional<Pose> findPose(KeyframeId id) const;
  /// Keyframes culled so far.
  size_t culledCount() const;
  /// Every keyframe id in increasing order.
  std::vector<KeyframeId> ids() const;
  std::map<KeyframeId, Pose> poses() const;
  /// Replaces the poses of the given keyframes, and the refined positions of the given
  /// features, at once (one lock: readers never see a mix). Keyframes culled meanwhile are
  /// left out.
  void setPoses(const std::map<KeyframeId, Pose>& poses, const PointRefinements& refined = {});
  /// A correction computed from the poses of keyframes up to `newest` (a snapshot): replaces
  /// their poses as setPoses() does, and moves the keyframes added since rigidly with `newest`,
  /// at once.
  void applyCorrection(const std::map<KeyframeId, Pose>& poses, KeyframeId newest);
  /// Holds keyframes where they are: a loaded map a session localizes in, which it may extend
  /// but not change (TrackerOptions::localizationOnly). setPoses() and applyCorrection() leave
  /// their poses and points as they are, and the optimizers hold them fixed.
  void anchor(const std::vector<KeyframeId>& ids);
  bool isAnchored(KeyframeId id) const;
  std::set<KeyframeId> anchoredIds() const;
  /// The keyframe's refined feature positions; null if none was refined.
  RefinedPoints refinedPoints(KeyframeId id) const;

  std::vector<KeyframeId> neighbours(KeyframeId id) const;
  /// Copies of the edges of one keyframe.
  std::vector<KeyframeEdge> edgesOf(KeyframeId id) const;
  /// Breadth-first rings from root: ring 0 = {root}; keyframes up to maxRing hops, id -> ring.
  /// Empty for a root not (or no longer) in the graph.
  std::map<KeyframeId, int> rings(KeyframeId root, int maxRing) const;
  /// Hop count between two keyframes, or -1 if more than maxHops apart (or unconnected).
  int hopDistance(KeyframeId a, KeyframeId b, int maxHops) const;
  /// Every keyframe connected to `id` through edges (its component of the map), with its hop
  /// count from `id`: rings() without a limit. Empty for an id not in the graph.
  std::map<KeyframeId, int> component(KeyframeId id) const;
  /// Whether a path of edges joins the two: the same component of the map.
  bool connected(KeyframeId a, KeyframeId b) const;
  /// Copies of the edges whose both endpoints are in the set.
  std::vector<KeyframeEdge> edgesWithin(const std::map<KeyframeId, int>& vertices) const;
  std::vector<KeyframeEdge> allEdges() const;
  /// The (i, j) pairs of all edges, i < j, without their matches: cheap, for display.
  std::vector<std::pair<KeyframeId, KeyframeId>> edgeIds() const;
  /// A copy of the whole graph taken under one lock, for a writer on another thread (live
  /// checkpoints): keyframes are shared (they are immutable), poses and edges copied.
  std::shared_ptr<KeyframeGraph> snapshot() const;
  GraphMemory memory() const;

 private:
  using EdgeKey = std::pair<KeyframeId, KeyframeId>;
  struct Culled {
    KeyframeId successor = 0;
    Pose successorToCulled = Pose::Identity();
  };
  std::map<KeyframeId, int> ringsLocked(KeyframeId root, int maxRing) const;
  void addMatchesLocked(KeyframeId a, KeyframeId b, const std::vector<PointMatch>& matchesAB);
  std::optional<Pose> poseLocked(KeyframeId id) const;

  mutable std::shared_mutex mutex_;
  std::map<KeyframeId, KeyframePtr> keyframes_;
  std::map<KeyframeId, Pose> poses_;
  std::map<KeyframeId, RefinedPoints> refined_;
  std::map<EdgeKey, KeyframeEdge> edges_;
  std::map<KeyframeId, std::vector<KeyframeId>> adjacency_;
  std::map<KeyframeId, Culled> culled_;
  std::set<KeyframeId> anchored_;
};

/// The poses of `ids` (all of `poses` when null) moved by one rigid motion, each re-projected
/// onto a rotation as a correction writes it (rounding must not compound from map to map).
std::map<KeyframeId, Pose> movedRigidly(const std::map<KeyframeId, Pose>& poses, const Pose& motion,
                                        const std::map<KeyframeId, int>* ids = nullptr);

}  // namespace slamdunk
