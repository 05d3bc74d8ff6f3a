#include <slamdunk/mapping/RandomizedKdTree.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace slamdunk {

namespace {
/// A leaf holds at most this many rows: fewer nodes to pass than with one row per leaf, and the
/// rows of a leaf lie next to each other in memory.
constexpr int kLeafRows = 4;
/// The split dimension is drawn among this many of highest variance.
constexpr int kSplitCandidates = 5;
/// The variances are estimated on at most this many rows of the node, evenly spaced.
constexpr int kVarianceSamples = 128;

/// xorshift32: a fixed sequence on every platform (std::uniform_int_distribution is not).
uint32_t nextRandom(uint32_t& state) {
  state ^= state << 13;
  state ^= state >> 17;
  state ^= state << 5;
  return state;
}

float squaredDistance(const float* a, const float* b, int n) {
  using Vec = Eigen::Map<const Eigen::VectorXf>;
  return (Vec(a, n) - Vec(b, n)).squaredNorm();
}

/// A branch not taken: the node, and a lower bound of its rows' squared distance to the query.
struct Branch {
  float bound;
  int node;
  bool operator>(const Branch& o) const { return bound > o.bound; }
};

/// The k best so far, nearest first.
class Nearest {
 public:
  Nearest(int k, int* indices, float* distances) : k_(k), idx_(indices), d_(distances) {}
  float worst() const { return n_ < k_ ? std::numeric_limits<float>::max() : d_[n_ - 1]; }
  void offer(float d2, int index) {
    if (n_ == k_ && !(d2 < d_[n_ - 1])) return;
    int i = n_ < k_ ? n_++ : n_ - 1;
    for (; i > 0 && d_[i - 1] > d2; --i) {
      d_[i] = d_[i - 1];
      idx_[i] = idx_[i - 1];
    }
    d_[i] = d2;
    idx_[i] = index;
  }
  int count() const { return n_; }

 private:
  int k_, n_ = 0;
  int* idx_;
  float* d_;
};
}  // namespace

RandomizedKdTree::RandomizedKdTree(const cv::Mat& rows, uint32_t seed) {
  if (rows.type() != CV_32F || !rows.isContinuous())
    throw std::invalid_argument("RandomizedKdTree: rows must be continuous CV_32F");
  cols_ = rows.cols;
  std::vector<int> order(rows.rows);
  std::iota(order.begin(), order.end(), 0);
  nodes_.reserve(2 * (rows.rows / kLeafRows + 1));
  uint32_t random = seed == 0 ? 0x9e3779b9u : seed;  // xorshift stays at 0 from 0
  if (rows.rows > 0) build(order, 0, rows.rows, rows, random);
  rowOf_ = order;
  points_.resize(size_t(rows.rows) * cols_);
  for (int i = 0; i < rows.rows; ++i)
    std::copy_n(rows.ptr<float>(order[i]), cols_, points_.data() + size_t(i) * cols_);
}

int RandomizedKdTree::build(std::vector<int>& order, int begin, int end, const cv::Mat& rows,
                            uint32_t& random) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  if (end - begin <= kLeafRows) {
    nodes_[id].begin = begin;
    nodes_[id].end = end;
    return id;
  }
  // Mean and variance of each dimension over evenly spaced rows of the node.
  const int n = end - begin, samples = std::min(n, kVarianceSamples);
  std::vector<double> sum(cols_, 0.0), sum2(cols_, 0.0);
  for (int s = 0; s < samples; ++s) {
    const float* r = rows.ptr<float>(order[begin + int(int64_t(s) * n / samples)]);
    for (int d = 0; d < cols_; ++d) {
      sum[d] += r[d];
      sum2[d] += double(r[d]) * r[d];
    }
  }
  std::vector<int> dims(cols_);
  std::iota(dims.begin(), dims.end(), 0);
  auto variance = [&](int d) {
    return sum2[d] / samples - (sum[d] / samples) * (sum[d] / samples);
  };
  const int candidates = std::min(cols_, kSplitCandidates);
  std::partial_sort(dims.begin(), dims.begin() + candidates, dims.end(), [&](int a, int b) {
    const double va = variance(a), vb = variance(b);
    return va != vb ? va > vb : a < b;
  });
  const int dim = dims[nextRandom(random) % candidates];
  const float split = static_cast<float>(sum[dim] / samples);

  auto below = [&](int row) { return rows.ptr<float>(row)[dim] < split; };
  int middle = static_cast<int>(
      std::stable_partition(order.begin() + begin, order.begin() + end, below) - order.begin());
  float used = split;
  if (middle == begin || middle == end) {
    // Every sampled value on one side (equal values): split the rows by their order instead.
    std::stable_sort(order.begin() + begin, order.begin() + end, [&](int a, int b) {
      return rows.ptr<float>(a)[dim] < rows.ptr<float>(b)[dim];
    });
    middle = begin + n / 2;
    used = rows.ptr<float>(order[middle])[dim];
  }
  const int lower = build(order, begin, middle, rows, random);
  const int upper = build(order, middle, end, rows, random);
  Node& node = nodes_[id];
  node.dim = dim;
  node.split = used;
  node.below = lower;
  node.above = upper;
  return id;
}

int RandomizedKdTree::knn(const float* query, int k, int checks, int* indices,
                          float* distances) const {
  if (k <= 0 || nodes_.empty()) return 0;
  Nearest nearest(k, indices, distances);
  // The branches not taken, nearest first; reused by each thread's searches.
  thread_local std::vector<Branch> heap;
  heap.clear();
  int compared = 0;
  int node = 0;
  float bound = 0;
  for (;;) {
    // Down to the query's leaf, keeping the other side of each split for later.
    while (nodes_[node].dim >= 0) {
      const Node& n = nodes_[node];
      const float diff = query[n.dim] - n.split;
      const int near = diff < 0 ? n.below : n.above, far = diff < 0 ? n.above : n.below;
      const float farBound = bound + diff * diff;
      if (farBound < nearest.worst()) {
        heap.push_back({farBound, far});
        std::push_heap(heap.begin(), heap.end(), std::greater<Branch>());
      }
      node = near;
    }
    const Node& leaf = nodes_[node];
    for (int i = leaf.begin; i < leaf.end; ++i)
      nearest.offer(squaredDistance(query, point(i), cols_), i);
    compared += leaf.end - leaf.begin;
    // The nearest branch left, unless enough rows were compared or no branch can do better.
    if (heap.empty() || compared >= checks) break;
    std::pop_heap(heap.begin(), heap.end(), std::greater<Branch>());
    const Branch next = heap.back();
    heap.pop_back();
    if (!(next.bound < nearest.worst())) break;
    node = next.node;
    bound = next.bound;
  }
  const int found = nearest.count();
  for (int j = 0; j < found; ++j) {
    indices[j] = rowOf_[indices[j]];
    distances[j] = std::sqrt(std::max(0.f, distances[j]));
  }
  return found;
}

}  // namespace slamdunk
