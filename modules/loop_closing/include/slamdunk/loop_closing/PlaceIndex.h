#pragma once
// An appearance index over the keyframes of the whole map: each keyframe as a bag of visual
// words (tf-idf, L1-normalised), an inverted index from words to keyframes, and a query that
// scores every keyframe sharing a word with the query (Σ min of the two weights: 1 for the
// same bag, 0 for nothing in common).

#include <slamdunk/graph/Keyframe.h>
#include <slamdunk/loop_closing/Vocabulary.h>

#include <map>
#include <utility>
#include <vector>

namespace slamdunk {

/// (word, weight) sorted by word; weights sum to 1.
using BagOfWords = std::vector<std::pair<uint32_t, float>>;

class PlaceIndex {
 public:
  PlaceIndex() = default;
  /// `idfSamples`: the word ids of each of the keyframes the words were learned from, which
  /// tell how common each word is (a word in every keyframe weighs nothing).
  PlaceIndex(Vocabulary vocabulary, const std::vector<std::vector<uint32_t>>& idfSamples);

  bool ready() const { return !vocabulary_.empty(); }
  const Vocabulary& vocabulary() const { return vocabulary_; }
  BagOfWords describe(const cv::Mat& descriptors) const;
  /// Indexes a keyframe (replacing an earlier bag of the same id).
  void add(KeyframeId id, BagOfWords bag);
  void remove(KeyframeId id);
  size_t size() const { return bags_.size(); }
  bool contains(KeyframeId id) const { return bags_.count(id) > 0; }
  /// Every indexed keyframe sharing a word with `bag`, with its score, by increasing id.
  std::vector<std::pair<KeyframeId, double>> query(const BagOfWords& bag) const;
  /// Score of two indexed keyframes (0 when either is not indexed).
  double score(KeyframeId a, KeyframeId b) const;

 private:
  Vocabulary vocabulary_;
  std::vector<float> idf_;  ///< per word
  std::map<KeyframeId, BagOfWords> bags_;
  std::vector<std::vector<std::pair<KeyframeId, float>>> inverted_;  ///< per word
};

double bagScore(const BagOfWords& a, const BagOfWords& b);

}  // namespace slamdunk
