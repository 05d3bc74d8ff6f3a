#pragma once
// The feature pool (paper Sec. 4.1-4.2): descriptors of the active keyframes, indexed for
// approximate nearest-neighbour search and matched with the multi-view ratio test (next-closest
// feature of the *same* keyframe).
//
// A pool is a list of parts, each one index over the features of some keyframes: the window's
// keyframes in one part, and each keyframe spawned since in a small part of its own. A part is
// built once, from a snapshot of keyframes and poses (no graph access), so it can be built on
// any thread and shared by every pool that contains it.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/EnumNames.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace cv::flann {
class Index;
}

namespace slamdunk {

class RandomizedKdTree;

/// The nearest-neighbour index of a pool part (float descriptors; binary ones always use LSH).
enum class PoolIndexType {
  KdTree,     ///< RandomizedKdTree: one randomized k-d tree, approximate, `checks`
  Flann,      ///< OpenCV FLANN randomized KD-trees: approximate, `kdTrees` trees, `checks`
  Nanoflann,  ///< nanoflann single KD-tree: exact, cheap to build, slow to search in 64-D
  Exact       ///< brute force for every part: the reference for accuracy measurements
};
SLAMDUNK_ENUM_NAMES(PoolIndexType, {{PoolIndexType::KdTree, "kdtree"},
                                    {PoolIndexType::Flann, "flann"},
                                    {PoolIndexType::Nanoflann, "nanoflann"},
                                    {PoolIndexType::Exact, "exact"}});

struct FeaturePoolOptions {
  /// The own k-d tree: a window's part searched 2.4 times as fast as through FLANN's, for the
  /// same recall (bench-pool; docs/experiments.md).
  PoolIndexType index = PoolIndexType::KdTree;
  int kdTrees = 1;  ///< randomized KD-trees (FLANN, float descriptors)
  int checks = 96;  ///< descriptors compared per search (FLANN counts points)
  /// Parts of at most this many features are searched by brute force, whatever `index` says:
  /// exact, where the tree's search would miss some of a new keyframe's matches (the
  /// synthetic office's ATE doubles without it; docs/experiments.md).
  int bruteForceBelow = 1000;
  int neighbours = 4;          ///< k of the k-NN search used by the ratio test
  int searchThreads = 2;       ///< the only parallel block of tracking, as in the paper
  bool frustumFilter = true;   ///< keep only features visible from the window centre
  double frustumFar = 8.0;     ///< metres
  double frustumMargin = 0.1;  ///< fraction of the image size added around the frustum
  uint32_t seed = 7;           ///< KD-tree randomisation: same seed, same index, same matches
  /// A window's part holds at most this many features (0: no limit): those its keyframes saw
  /// from the directions nearest the window centre's, where their descriptors match best. In a
  /// room the window holds every keyframe; the budget bounds what a frame is matched against
  /// (docs/experiments.md: 7-Scenes' accuracy unchanged over five seeds).
  int budget = 10000;

  /// Its INI keys (in [local_map]), listed once for IniSectionReader and IniSectionWriter.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("pool_index", o.index);
    k("kdtree_trees", o.kdTrees);
    k("kdtree_checks", o.checks);
    k("pool_brute_force_below", o.bruteForceBelow);
    k("knn_neighbours", o.neighbours);
    k("search_threads", o.searchThreads);
    k("pool_frustum_filter", o.frustumFilter);
    k("pool_frustum_far", o.frustumFar);
    k("pool_frustum_margin", o.frustumMargin);
    k("kdtree_seed", o.seed);
    k("pool_budget", o.budget);
  }
};

struct PoolFeature {
  KeyframeId keyframe = 0;
  uint32_t index = 0;             ///< feature index within the keyframe
  Eigen::Vector3d pointKeyframe;  ///< in the keyframe's optical frame (refined if it was)
  Eigen::Vector3d pointWorld;     ///< with the keyframe pose at build time (poseAtBuild)
};

struct PoolMatch {
  uint32_t query = 0;  ///< feature index in the current frame
  uint32_t pool = 0;   ///< index into the pool
  double ratio = 0;    ///< θ' = d0 / d1
};

/// Keyframes and their poses, copied from the graph so that a part can be built off-thread.
struct PoolSnapshot {
  std::vector<KeyframePtr> keyframes;
  std::vector<Pose> poses;  ///< T_world_keyframe, one per keyframe
  /// The features' positions refined by the bundle adjustment, one per keyframe (null: as
  /// measured).
  std::vector<RefinedPoints> refined;
  /// Frustum of a camera with intrinsics K at `center` (world pose of its optical frame);
  /// unset: every feature is kept (a keyframe's own features need no frustum).
  std::optional<std::pair<Pose, CameraIntrinsics>> frustum;

  static PoolSnapshot of(const KeyframeGraph& graph, const std::vector<KeyframeId>& ids);
};

/// One index over the features of some keyframes. Immutable once built.
class PoolPart {
 public:
  PoolPart(const PoolSnapshot& snapshot, const FeaturePoolOptions& options);
  ~PoolPart();
  size_t size() const { return features_.size(); }
  const PoolFeature& feature(size_t i) const { return features_[i]; }
  const std::vector<KeyframeId>& keyframes() const { return keyframes_; }
  /// The keyframe's pose in the snapshot the part was built from (null: not in the part).
  const Pose* poseAtBuild(KeyframeId id) const;
  bool binary() const { return binary_; }
  bool bruteForce() const { return !index_ && !nanoflann_ && !kdTree_; }
  /// k nearest neighbours of each query row: indices (CV_32S, -1 = none) and distances
  /// (CV_32F: Euclidean for float descriptors, bit counts for binary ones).
  void knnSearch(const cv::Mat& queries, int k, int checks, cv::Mat& indices,
                 cv::Mat& distances) const;

 private:
  /// A keyframe's descriptor of one feature, as the keyframe stores it.
  struct DescriptorRow {
    const uchar* data;
    int type;
  };
  /// Keeps the `budget` features seen from the directions nearest `centre`'s (with their
  /// descriptor rows).
  void keepBestSeen(const Eigen::Vector3d& centre, size_t budget, std::vector<DescriptorRow>& rows);
  std::vector<PoolFeature> features_;
  std::vector<KeyframeId> keyframes_;
  std::vector<Pose> keyframePoses_;  ///< snapshot pose of each of keyframes_
  cv::Mat descriptors_;
  bool binary_ = false;
  std::unique_ptr<cv::flann::Index> index_;
  std::unique_ptr<RandomizedKdTree> kdTree_;
  struct NanoflannIndex;
  std::unique_ptr<NanoflannIndex> nanoflann_;
};

class FeaturePool {
 public:
  explicit FeaturePool(FeaturePoolOptions options = {});

  /// Replaces the pool by one part over the features of `active` keyframes that lie in the
  /// frustum of a camera with intrinsics K at `center` (world pose of the optical frame).
  void build(const KeyframeGraph& graph, const std::vector<KeyframeId>& active, const Pose& center,
             const CameraIntrinsics& K);
  /// Adds a part built elsewhere; indices of the features already in the pool do not change.
  void append(std::shared_ptr<const PoolPart> part);
  /// Matches each query descriptor against every part; keeps matches with θ' < ratioThreshold.
  std::vector<PoolMatch> match(const cv::Mat& queryDescriptors, double ratioThreshold) const;

  size_t size() const { return size_; }
  const PoolFeature& feature(size_t i) const;
  /// Keyframes with features in the pool, in the order of the parts.
  std::vector<KeyframeId> keyframes() const;
  bool contains(KeyframeId id) const;
  /// The pose the keyframe had when its part was built: world points of the pool, and a pose
  /// registered against them, are in that world, which optimization may have moved since.
  std::optional<Pose> poseAtBuild(KeyframeId id) const;
  const std::vector<std::shared_ptr<const PoolPart>>& parts() const { return parts_; }
  const FeaturePoolOptions& options() const { return options_; }

 private:
  FeaturePoolOptions options_;
  std::vector<std::shared_ptr<const PoolPart>> parts_;
  std::vector<size_t> offsets_;  ///< index of each part's first feature in the pool
  size_t size_ = 0;
};

}  // namespace slamdunk
