#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/loop_closing/Vocabulary.h>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>

namespace slamdunk {

namespace {

float squaredDistance(const float* a, const float* b, int dims) {
  float sum = 0;
  for (int d = 0; d < dims; ++d) {
    const float diff = a[d] - b[d];
    sum += diff * diff;
  }
  return sum;
}

int nearestRow(const cv::Mat& centres, const float* x) {
  int best = 0;
  float bestDistance = std::numeric_limits<float>::max();
  for (int c = 0; c < centres.rows; ++c) {
    const float d = squaredDistance(centres.ptr<float>(c), x, centres.cols);
    if (d < bestDistance) {
      bestDistance = d;
      best = c;
    }
  }
  return best;
}

/// k-means of the rows (CV_32F): k-means++ start, then Lloyd rounds. Fewer rows than k: the
/// rows themselves are the centres.
cv::Mat kMeans(const cv::Mat& rows, int k, int iterations, std::mt19937& random) {
  if (rows.rows <= k) return rows.clone();
  cv::Mat centres(k, rows.cols, CV_32F);
  std::vector<float> nearest(rows.rows, std::numeric_limits<float>::max());
  int chosen = std::uniform_int_distribution<int>(0, rows.rows - 1)(random);
  for (int c = 0; c < k; ++c) {
    rows.row(chosen).copyTo(centres.row(c));
    double total = 0;
    for (int r = 0; r < rows.rows; ++r) {
      nearest[r] = std::min(nearest[r],
                            squaredDistance(rows.ptr<float>(r), centres.ptr<float>(c), rows.cols));
      total += nearest[r];
    }
    if (c + 1 == k) break;
    // The next centre far from those chosen: drawn with probability ∝ squared distance.
    double pick = std::uniform_real_distribution<double>(0, total)(random);
    chosen = rows.rows - 1;
    for (int r = 0; r < rows.rows; ++r) {
      pick -= nearest[r];
      if (pick <= 0) {
        chosen = r;
        break;
      }
    }
  }
  std::vector<int> label(rows.rows, 0);
  for (int it = 0; it < iterations; ++it) {
    for (int r = 0; r < rows.rows; ++r) label[r] = nearestRow(centres, rows.ptr<float>(r));
    cv::Mat sums = cv::Mat::zeros(k, rows.cols, CV_64F);
    std::vector<int> counts(k, 0);
    for (int r = 0; r < rows.rows; ++r) {
      ++counts[label[r]];
      double* s = sums.ptr<double>(label[r]);
      const float* x = rows.ptr<float>(r);
      for (int d = 0; d < rows.cols; ++d) s[d] += x[d];
    }
    for (int c = 0; c < k; ++c) {
      if (counts[c] == 0) continue;  // an empty cluster keeps its centre
      float* centre = centres.ptr<float>(c);
      const double* s = sums.ptr<double>(c);
      for (int d = 0; d < rows.cols; ++d) centre[d] = static_cast<float>(s[d] / counts[c]);
    }
  }
  return centres;
}
}  // namespace

cv::Mat descriptorRowsAsFloat(const cv::Mat& descriptors) {
  if (descriptors.type() != CV_8U) return matchableDescriptors(descriptors);  // floats
  cv::Mat bits(descriptors.rows, descriptors.cols * 8, CV_32F);
  for (int r = 0; r < descriptors.rows; ++r) {
    const uint8_t* in = descriptors.ptr<uint8_t>(r);
    float* out = bits.ptr<float>(r);
    for (int c = 0; c < descriptors.cols; ++c)
      for (int b = 0; b < 8; ++b) out[c * 8 + b] = (in[c] >> b) & 1 ? 1.f : 0.f;
  }
  return bits;
}

Vocabulary Vocabulary::learn(const cv::Mat& descriptors, int branching, int levels, int iterations,
                             uint32_t seed) {
  if (branching < 2) throw std::invalid_argument("vocabulary branching must be at least 2");
  if (levels < 1) throw std::invalid_argument("vocabulary levels must be at least 1");
  if (descriptors.rows == 0) throw std::invalid_argument("no descriptors to learn words from");
  const cv::Mat rows = descriptorRowsAsFloat(descriptors);
  std::mt19937 random(seed);
  Vocabulary v;
  v.dims_ = rows.cols;
  v.learnNode(rows, 0, branching, levels, iterations, &random);
  return v;
}

int Vocabulary::learnNode(const cv::Mat& rows, int level, int branching, int levels, int iterations,
                          void* random) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  cv::Mat centres = kMeans(rows, branching, iterations, *static_cast<std::mt19937*>(random));
  std::vector<int> children(centres.rows);
  if (level + 1 == levels || rows.rows <= branching) {
    for (int& c : children) c = -1 - static_cast<int>(words_++);
  } else {
    std::vector<std::vector<int>> members(centres.rows);
    for (int r = 0; r < rows.rows; ++r)
      members[nearestRow(centres, rows.ptr<float>(r))].push_back(r);
    for (int c = 0; c < centres.rows; ++c) {
      if (members[c].empty()) {
        children[c] = -1 - static_cast<int>(words_++);
        continue;
      }
      cv::Mat subset(static_cast<int>(members[c].size()), rows.cols, CV_32F);
      for (size_t i = 0; i < members[c].size(); ++i)
        rows.row(members[c][i]).copyTo(subset.row(static_cast<int>(i)));
      children[c] = learnNode(subset, level + 1, branching, levels, iterations, random);
    }
  }
  nodes_[index].centres = std::move(centres);  // after the recursion: nodes_ may have moved
  nodes_[index].children = std::move(children);
  return index;
}

std::vector<uint32_t> Vocabulary::words(const cv::Mat& descriptors) const {
  std::vector<uint32_t> out;
  if (empty() || descriptors.rows == 0) return out;
  const cv::Mat rows = descriptorRowsAsFloat(descriptors);
  if (rows.cols != dims_)
    throw std::invalid_argument("descriptors do not have the vocabulary's length");
  out.reserve(rows.rows);
  for (int r = 0; r < rows.rows; ++r) {
    const float* x = rows.ptr<float>(r);
    int child = 0;
    do {
      const Node& node = nodes_[child];
      child = node.children[nearestRow(node.centres, x)];
    } while (child >= 0);
    out.push_back(static_cast<uint32_t>(-1 - child));
  }
  return out;
}

}  // namespace slamdunk
