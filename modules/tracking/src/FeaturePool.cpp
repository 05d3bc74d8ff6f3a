#include <slamdunk/tracking/DepthNoiseModel.h>
#include <slamdunk/tracking/FeaturePool.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/flann.hpp>

#include <cmath>
#include <cstdlib>

namespace slamdunk {

FeaturePool::FeaturePool(FeaturePoolOptions options) : options_(options) {}
FeaturePool::~FeaturePool() = default;
FeaturePool::FeaturePool(FeaturePool&&) noexcept = default;
FeaturePool& FeaturePool::operator=(FeaturePool&&) noexcept = default;

namespace {
bool insideFrustum(const Eigen::Vector3d& pc, const CameraIntrinsics& K,
                   const FeaturePoolOptions& o) {
  if (pc.z() <= 0.05 || pc.z() > o.frustumFar) return false;
  const Eigen::Vector2d uv = K.project(pc);
  const double mu = o.frustumMargin * K.width, mv = o.frustumMargin * K.height;
  return uv.x() >= -mu && uv.x() < K.width + mu && uv.y() >= -mv && uv.y() < K.height + mv;
}
}  // namespace

void FeaturePool::build(const KeyframeGraph& graph, const std::vector<KeyframeId>& active,
                        const Pose& center, const CameraIntrinsics& K) {
  features_.clear();
  keyframes_ = active;
  index_.reset();
  descriptors_ = cv::Mat();
  const Pose worldToCenter = center.inverse();
  const DepthNoiseModel noise;
  std::vector<cv::Mat> rows;
  for (KeyframeId id : active) {
    const KeyframePtr kf = graph.keyframe(id);
    const Pose T = graph.pose(id);
    const FeatureSet& fs = kf->features;
    for (size_t i = 0; i < fs.size(); ++i) {
      const Eigen::Vector3d pw = T * fs.points[i];
      if (options_.frustumFilter && !insideFrustum(worldToCenter * pw, K, options_)) continue;
      const Eigen::Matrix3d R = T.linear();
      features_.push_back({id, static_cast<uint32_t>(i), fs.points[i], pw,
                           R * noise.covariance(fs.points[i]) * R.transpose()});
      rows.push_back(fs.descriptors.row(static_cast<int>(i)));
    }
  }
  if (rows.empty()) return;
  cv::vconcat(rows, descriptors_);
  binary_ = descriptors_.type() == CV_8U;
  // OpenCV's FLANN draws its random tree splits from std::rand: seed it for repeatable runs.
  std::srand(options_.seed);
  if (binary_)
    index_ = std::make_unique<cv::flann::Index>(descriptors_, cv::flann::LshIndexParams(12, 16, 2),
                                                cvflann::FLANN_DIST_HAMMING);
  else
    index_ = std::make_unique<cv::flann::Index>(descriptors_,
                                                cv::flann::KDTreeIndexParams(options_.kdTrees));
}

std::vector<PoolMatch> FeaturePool::match(const cv::Mat& query, double ratioThreshold) const {
  std::vector<PoolMatch> out;
  if (!index_ || query.empty()) return out;
  const int k = std::min<int>(options_.neighbours, static_cast<int>(features_.size()));
  if (k < 2) return out;
  cv::Mat queryConv = query;
  if (!binary_ && query.type() != CV_32F) query.convertTo(queryConv, CV_32F);

  cv::Mat indices(query.rows, k, CV_32S), dists(query.rows, k, binary_ ? CV_32S : CV_32F);
  const int threads = std::max(1, std::min(options_.searchThreads, query.rows));
  const cv::flann::SearchParams params(options_.checks);
  // Each stripe searches its own block of queries; results land in disjoint rows.
  cv::parallel_for_(
      cv::Range(0, threads),
      [&](const cv::Range& r) {
        for (int t = r.start; t < r.end; ++t) {
          const int a = query.rows * t / threads, b = query.rows * (t + 1) / threads;
          if (a == b) continue;
          cv::Mat idx = indices.rowRange(a, b), dst = dists.rowRange(a, b);
          cv::Mat idxOut, dstOut;
          index_->knnSearch(queryConv.rowRange(a, b), idxOut, dstOut, k, params);
          idxOut.copyTo(idx);
          dstOut.convertTo(dst, dst.type());
        }
      },
      threads);

  for (int q = 0; q < query.rows; ++q) {
    const int* idx = indices.ptr<int>(q);
    auto distance = [&](int j) {
      // FLANN's L2 distances are squared; Hamming ones are bit counts.
      return binary_ ? static_cast<double>(dists.at<int>(q, j))
                     : std::sqrt(std::max(0.f, dists.at<float>(q, j)));
    };
    if (idx[0] < 0 || idx[0] >= static_cast<int>(features_.size())) continue;
    const KeyframeId kf = features_[idx[0]].keyframe;
    const double d0 = distance(0);
    // d1: the next-closest feature of the same keyframe. If none is among the k neighbours,
    // it is at least as far as the k-th one, which bounds the ratio from above.
    double d1 = -1;
    int last = 0;
    for (int j = 1; j < k; ++j) {
      if (idx[j] < 0 || idx[j] >= static_cast<int>(features_.size())) break;
      last = j;
      if (features_[idx[j]].keyframe == kf) {
        d1 = distance(j);
        break;
      }
    }
    if (d1 < 0) {
      if (last == 0) continue;
      d1 = distance(last);
    }
    const double ratio = d1 > 0 ? d0 / d1 : 1.0;
    if (ratio < ratioThreshold)
      out.push_back({static_cast<uint32_t>(q), static_cast<uint32_t>(idx[0]), ratio});
  }
  return out;
}

}  // namespace slamdunk
