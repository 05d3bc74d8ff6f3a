#pragma once
// Visual words learned from the session's own descriptors, so that no vocabulary file has to
// be shipped or downloaded: a k-means tree (up to branching^levels words, its leaves), seeded,
// so that a run learns the same words every time. Binary descriptors (ORB) are clustered as
// their bits.

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace slamdunk {

class Vocabulary {
 public:
  Vocabulary() = default;
  /// Learns the words from the rows of `descriptors` (floats, or CV_8U binary): `branching`
  /// clusters of the rows, `branching` clusters within each, and so on down `levels` levels,
  /// each by `iterations` rounds of Lloyd's algorithm from a k-means++ start drawn with `seed`.
  /// A cluster of no more rows than `branching` takes its rows as its children.
  static Vocabulary learn(const cv::Mat& descriptors, int branching, int levels, int iterations,
                          uint32_t seed);

  bool empty() const { return nodes_.empty(); }
  /// Number of words (ids run from 0 to size() - 1).
  size_t size() const { return words_; }
  /// The word of each row of `descriptors` (floats however stored, or binary, as learned from).
  std::vector<uint32_t> words(const cv::Mat& descriptors) const;

 private:
  struct Node {
    cv::Mat centres;            ///< one row per child (CV_32F)
    std::vector<int> children;  ///< per child: its node, or -1 - its word for a leaf
  };
  int learnNode(const cv::Mat& rows, int level, int branching, int levels, int iterations,
                void* random);

  std::vector<Node> nodes_;  ///< nodes_[0] is the root
  size_t words_ = 0;
  int dims_ = 0;
};

/// Rows as CV_32F: float descriptors as they are (8-bit codes read back), binary ones as one float
/// (0 or 1) per bit, so that squared Euclidean distances are Hamming distances.
cv::Mat descriptorRowsAsFloat(const cv::Mat& descriptors);

}  // namespace slamdunk
