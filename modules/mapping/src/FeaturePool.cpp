#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/mapping/RandomizedKdTree.h>

#include <nanoflann.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/flann.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>

namespace slamdunk {

namespace {
bool insideFrustum(const Eigen::Vector3d& pc, const CameraIntrinsics& K,
                   const FeaturePoolOptions& o) {
  if (pc.z() <= 0.05 || pc.z() > o.frustumFar) return false;
  const Eigen::Vector2d uv = K.project(pc);
  const double mu = o.frustumMargin * K.width, mv = o.frustumMargin * K.height;
  return uv.x() >= -mu && uv.x() < K.width + mu && uv.y() >= -mv && uv.y() < K.height + mv;
}

}  // namespace

/// nanoflann's view of the descriptor rows, and its tree over them.
struct PoolPart::NanoflannIndex {
  struct Rows {
    const cv::Mat& m;
    size_t kdtree_get_point_count() const { return static_cast<size_t>(m.rows); }
    float kdtree_get_pt(size_t i, size_t d) const { return m.ptr<float>(static_cast<int>(i))[d]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Rows>, Rows,
                                                   -1, uint32_t>;
  Rows rows;
  Tree tree;
  explicit NanoflannIndex(const cv::Mat& m)
      : rows{m}, tree(m.cols, rows, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    tree.buildIndex();
  }
};

PoolSnapshot PoolSnapshot::of(const KeyframeGraph& graph, const std::vector<KeyframeId>& ids) {
  PoolSnapshot s;
  s.keyframes.reserve(ids.size());
  s.poses.reserve(ids.size());
  for (KeyframeId id : ids) {
    s.keyframes.push_back(graph.keyframe(id));
    s.poses.push_back(graph.pose(id));
    s.refined.push_back(graph.refinedPoints(id));
  }
  return s;
}

PoolPart::PoolPart(const PoolSnapshot& snapshot, const FeaturePoolOptions& options) {
  const Pose worldToCenter =
      snapshot.frustum ? snapshot.frustum->first.inverse() : Pose::Identity();
  const bool filter = snapshot.frustum && options.frustumFilter;
  std::vector<DescriptorRow> rows;
  int cols = 0, type = -1;
  for (size_t k = 0; k < snapshot.keyframes.size(); ++k) {
    const Keyframe& kf = *snapshot.keyframes[k];
    const Pose& T = snapshot.poses[k];
    const FeatureSet& fs = kf.features;
    if (fs.size() == 0) continue;
    if (type < 0) {
      type = fs.descriptors.type();
      cols = fs.descriptors.cols;
    }
    keyframes_.push_back(kf.id);
    keyframePoses_.push_back(T);
    const std::vector<Eigen::Vector3d>& points =
        k < snapshot.refined.size() && snapshot.refined[k] ? *snapshot.refined[k] : fs.points;
    for (size_t i = 0; i < fs.size(); ++i) {
      const Eigen::Vector3d pw = T * points[i];
      if (filter && !insideFrustum(worldToCenter * pw, snapshot.frustum->second, options)) continue;
      features_.push_back({kf.id, static_cast<uint32_t>(i), points[i], pw});
      rows.push_back({fs.descriptors.ptr(static_cast<int>(i)), fs.descriptors.type()});
    }
  }
  if (features_.empty()) return;
  if (snapshot.frustum && options.budget > 0 &&
      features_.size() > static_cast<size_t>(options.budget))
    keepBestSeen(snapshot.frustum->first.translation(), static_cast<size_t>(options.budget), rows);
  binary_ = type == CV_8U;
  descriptors_.create(static_cast<int>(features_.size()), cols, binary_ ? CV_8U : CV_32F);
  const size_t rowBytes = descriptors_.elemSize() * cols;
  for (int r = 0; r < descriptors_.rows; ++r) {
    if (rows[r].type == descriptors_.type())
      std::memcpy(descriptors_.ptr(r), rows[r].data, rowBytes);
    else  // keyframes keep half floats, or 8-bit codes far from the window: searched as floats
      matchableRow(rows[r].data, rows[r].type, cols, descriptors_.ptr<float>(r));
  }
  if (options.index == PoolIndexType::Exact ||
      features_.size() <= static_cast<size_t>(std::max(0, options.bruteForceBelow)))
    return;  // searched by brute force
  if (!binary_ && options.index == PoolIndexType::Nanoflann) {
    nanoflann_ = std::make_unique<NanoflannIndex>(descriptors_);
    return;
  }
  if (!binary_ && options.index == PoolIndexType::KdTree) {
    kdTree_ = std::make_unique<RandomizedKdTree>(descriptors_, options.seed);
    descriptors_.release();  // the tree keeps its own copy, in its leaves' order
    return;
  }
  // OpenCV's FLANN draws its tree splits from cv::theRNG(), which is per thread: seeding it
  // here makes the trees depend on the snapshot and the seed only, whichever thread builds them.
  cv::theRNG() = cv::RNG(options.seed);
  if (binary_)
    index_ = std::make_unique<cv::flann::Index>(descriptors_, cv::flann::LshIndexParams(12, 16, 2),
                                                cvflann::FLANN_DIST_HAMMING);
  else
    index_ = std::make_unique<cv::flann::Index>(descriptors_,
                                                cv::flann::KDTreeIndexParams(options.kdTrees));
#if CV_VERSION_MAJOR > 4 || (CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR >= 6)
  // cv::flann::Index searches a copy of the rows it keeps itself (since OpenCV 4.6, seen in a
  // heap profile here): ours would only double the pool's memory.
  descriptors_.release();
#endif
}

void PoolPart::keepBestSeen(const Eigen::Vector3d& centre, size_t budget,
                            std::vector<DescriptorRow>& rows) {
  // Cosine between the keyframe's ray to the point and the centre's: 1 = the same direction.
  std::map<KeyframeId, Eigen::Vector3d> keyframeCentres;
  for (size_t k = 0; k < keyframes_.size(); ++k)
    keyframeCentres[keyframes_[k]] = keyframePoses_[k].translation();
  std::vector<double> alike(features_.size());
  for (size_t i = 0; i < features_.size(); ++i) {
    const PoolFeature& f = features_[i];
    const Eigen::Vector3d fromKeyframe = f.pointWorld - keyframeCentres.at(f.keyframe);
    const Eigen::Vector3d fromCentre = f.pointWorld - centre;
    const double norms = fromKeyframe.norm() * fromCentre.norm();
    alike[i] = norms > 0 ? fromKeyframe.dot(fromCentre) / norms : -1;
  }
  std::vector<size_t> order(features_.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return alike[a] > alike[b]; });
  order.resize(budget);
  std::sort(order.begin(), order.end());  // the kept ones in their first order
  std::vector<PoolFeature> kept;
  std::vector<DescriptorRow> keptRows;
  for (size_t i : order) {
    kept.push_back(features_[i]);
    keptRows.push_back(rows[i]);
  }
  features_ = std::move(kept);
  rows = std::move(keptRows);
}

PoolPart::~PoolPart() = default;

const Pose* PoolPart::poseAtBuild(KeyframeId id) const {
  const auto it = std::find(keyframes_.begin(), keyframes_.end(), id);
  return it == keyframes_.end() ? nullptr : &keyframePoses_[it - keyframes_.begin()];
}

void PoolPart::knnSearch(const cv::Mat& queries, int k, int checks, cv::Mat& indices,
                         cv::Mat& distances) const {
  // Both own trees answer one query at a time: k rows, the missing ones marked -1.
  auto eachQuery = [&](auto&& search) {
    indices.create(queries.rows, k, CV_32S);
    distances.create(queries.rows, k, CV_32F);
    for (int q = 0; q < queries.rows; ++q) {
      int* idx = indices.ptr<int>(q);
      float* d = distances.ptr<float>(q);
      const int found = search(queries.ptr<float>(q), idx, d);
      std::fill(idx + found, idx + k, -1);
      std::fill(d + found, d + k, 0.f);
    }
  };
  if (nanoflann_) {
    std::vector<uint32_t> ids(k);
    std::vector<float> d2(k);
    eachQuery([&](const float* query, int* idx, float* d) {
      const int found =
          static_cast<int>(nanoflann_->tree.knnSearch(query, k, ids.data(), d2.data()));
      for (int j = 0; j < found; ++j) {
        idx[j] = static_cast<int>(ids[j]);
        d[j] = std::sqrt(std::max(0.f, d2[j]));
      }
      return found;
    });
    return;
  }
  if (kdTree_) {
    eachQuery([&](const float* query, int* idx, float* d) {
      return kdTree_->knn(query, k, checks, idx, d);
    });
    return;
  }
  if (bruteForce()) {
    // Sorted k nearest, plain (not squared) L2 or Hamming distances.
    cv::Mat dst;
    cv::batchDistance(queries, descriptors_, dst, binary_ ? CV_32S : CV_32F, indices,
                      binary_ ? cv::NORM_HAMMING : cv::NORM_L2, k);
    if (binary_)
      dst.convertTo(distances, CV_32F);
    else
      distances = dst;
    return;
  }
  cv::Mat idx, dst;
  index_->knnSearch(queries, idx, dst, k, cv::flann::SearchParams(checks));
  indices = idx;
  if (binary_) {
    dst.convertTo(distances, CV_32F);
  } else {
    // FLANN's L2 distances are squared.
    distances.create(dst.rows, dst.cols, CV_32F);
    for (int r = 0; r < dst.rows; ++r)
      for (int c = 0; c < dst.cols; ++c)
        distances.at<float>(r, c) = std::sqrt(std::max(0.f, dst.at<float>(r, c)));
  }
}

FeaturePool::FeaturePool(FeaturePoolOptions options) : options_(options) {}

void FeaturePool::build(const KeyframeGraph& graph, const std::vector<KeyframeId>& active,
                        const Pose& center, const CameraIntrinsics& K) {
  parts_.clear();
  offsets_.clear();
  size_ = 0;
  PoolSnapshot snapshot = PoolSnapshot::of(graph, active);
  snapshot.frustum = std::make_pair(center, K);
  append(std::make_shared<const PoolPart>(snapshot, options_));
}

void FeaturePool::append(std::shared_ptr<const PoolPart> part) {
  if (!part || part->size() == 0) return;
  offsets_.push_back(size_);
  size_ += part->size();
  parts_.push_back(std::move(part));
}

const PoolFeature& FeaturePool::feature(size_t i) const {
  const size_t p = std::upper_bound(offsets_.begin(), offsets_.end(), i) - offsets_.begin() - 1;
  return parts_[p]->feature(i - offsets_[p]);
}

std::vector<KeyframeId> FeaturePool::keyframes() const {
  std::vector<KeyframeId> out;
  for (const auto& p : parts_) out.insert(out.end(), p->keyframes().begin(), p->keyframes().end());
  return out;
}

bool FeaturePool::contains(KeyframeId id) const { return poseAtBuild(id).has_value(); }

std::optional<Pose> FeaturePool::poseAtBuild(KeyframeId id) const {
  for (const auto& p : parts_)
    if (const Pose* pose = p->poseAtBuild(id)) return *pose;
  return std::nullopt;
}

std::vector<PoolMatch> FeaturePool::match(const cv::Mat& query, double ratioThreshold) const {
  std::vector<PoolMatch> out;
  if (parts_.empty() || query.empty()) return out;
  const bool binary = parts_.front()->binary();
  cv::Mat queryConv = query;
  if (!binary && query.type() != CV_32F) query.convertTo(queryConv, CV_32F);

  // Per query, the best candidate over all parts: the nearest feature d0 and its ratio, d1
  // being the next-closest feature of the same keyframe (a keyframe lives in one part only).
  struct Best {
    float d0 = -1;
    double ratio = 1;
    uint32_t pool = 0;
  };
  std::vector<Best> best(query.rows);
  const int threads = std::max(1, std::min(options_.searchThreads, query.rows));
  // Each block of queries lands in its own entries. More blocks than threads, handed out as
  // threads free up: when the pool worker shares a core with one search thread, the other
  // takes more blocks instead of waiting for the slowed one (the tail of the frame times).
  const int blocks = threads == 1 ? 1 : std::min(query.rows, 8 * threads);
  cv::parallel_for_(
      cv::Range(0, blocks),
      [&](const cv::Range& range) {
        for (int t = range.start; t < range.end; ++t) {
          const int a = query.rows * t / blocks, b = query.rows * (t + 1) / blocks;
          if (a == b) continue;
          for (size_t p = 0; p < parts_.size(); ++p) {
            const PoolPart& part = *parts_[p];
            const int k = std::min<int>(options_.neighbours, static_cast<int>(part.size()));
            if (k < 2) continue;
            cv::Mat indices, dists;
            part.knnSearch(queryConv.rowRange(a, b), k, options_.checks, indices, dists);
            for (int q = 0; q < b - a; ++q) {
              const int* idx = indices.ptr<int>(q);
              const float* d = dists.ptr<float>(q);
              if (idx[0] < 0 || idx[0] >= static_cast<int>(part.size())) continue;
              Best& bq = best[a + q];
              if (bq.d0 >= 0 && d[0] >= bq.d0) continue;  // an earlier part has a nearer one
              const KeyframeId kf = part.feature(idx[0]).keyframe;
              // If no feature of the same keyframe is among the k neighbours, d1 is at least
              // the k-th distance, which bounds the ratio from above.
              double d1 = -1;
              int last = 0;
              for (int j = 1; j < k; ++j) {
                if (idx[j] < 0 || idx[j] >= static_cast<int>(part.size())) break;
                last = j;
                if (part.feature(idx[j]).keyframe == kf) {
                  d1 = d[j];
                  break;
                }
              }
              if (d1 < 0) {
                if (last == 0) continue;
                d1 = d[last];
              }
              bq.d0 = d[0];
              bq.ratio = d1 > 0 ? d[0] / d1 : 1.0;
              bq.pool = static_cast<uint32_t>(offsets_[p] + idx[0]);
            }
          }
        }
      },
      blocks);

  for (int q = 0; q < query.rows; ++q)
    if (best[q].d0 >= 0 && best[q].ratio < ratioThreshold)
      out.push_back({static_cast<uint32_t>(q), best[q].pool, best[q].ratio});
  return out;
}

}  // namespace slamdunk
