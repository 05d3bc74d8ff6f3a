#pragma once
// The feature pool (paper Sec. 4.1-4.2): descriptors of the active keyframes in one index,
// matched with the multi-view ratio test (next-closest feature of the *same* keyframe).

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <memory>
#include <vector>

namespace cv::flann {
class Index;
}

namespace slamdunk {

struct FeaturePoolOptions {
  int kdTrees = 4;             ///< randomized KD-trees (float descriptors)
  int checks = 16;             ///< leaves visited per search
  int neighbours = 4;          ///< k of the k-NN search used by the ratio test
  int searchThreads = 2;       ///< the only parallel block of tracking, as in the paper
  bool frustumFilter = true;   ///< keep only features visible from the window centre
  double frustumFar = 8.0;     ///< metres
  double frustumMargin = 0.1;  ///< fraction of the image size added around the frustum
  uint32_t seed = 7;           ///< KD-tree randomisation: same seed, same index, same matches
};

struct PoolFeature {
  KeyframeId keyframe = 0;
  uint32_t index = 0;             ///< feature index within the keyframe
  Eigen::Vector3d pointKeyframe;  ///< in the keyframe's optical frame
  Eigen::Vector3d pointWorld;     ///< with the keyframe pose at build time
  Eigen::Matrix3d covarianceWorld = Eigen::Matrix3d::Identity();  ///< depth noise, world frame
};

struct PoolMatch {
  uint32_t query = 0;  ///< feature index in the current frame
  uint32_t pool = 0;   ///< index into the pool
  double ratio = 0;    ///< θ' = d0 / d1
};

class FeaturePool {
 public:
  explicit FeaturePool(FeaturePoolOptions options = {});
  ~FeaturePool();
  FeaturePool(FeaturePool&&) noexcept;
  FeaturePool& operator=(FeaturePool&&) noexcept;

  /// Gathers the features of `active` keyframes that lie in the frustum of a camera with
  /// intrinsics K at `center` (world pose of the optical frame) and indexes them.
  void build(const KeyframeGraph& graph, const std::vector<KeyframeId>& active, const Pose& center,
             const CameraIntrinsics& K);
  /// Matches each query descriptor; keeps matches with θ' < ratioThreshold.
  std::vector<PoolMatch> match(const cv::Mat& queryDescriptors, double ratioThreshold) const;

  size_t size() const { return features_.size(); }
  const PoolFeature& feature(size_t i) const { return features_[i]; }
  const std::vector<KeyframeId>& keyframes() const { return keyframes_; }

 private:
  FeaturePoolOptions options_;
  std::vector<PoolFeature> features_;
  std::vector<KeyframeId> keyframes_;
  cv::Mat descriptors_;
  bool binary_ = false;
  std::unique_ptr<cv::flann::Index> index_;
};

}  // namespace slamdunk
