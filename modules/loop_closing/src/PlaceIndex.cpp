#include <slamdunk/loop_closing/PlaceIndex.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace slamdunk {

PlaceIndex::PlaceIndex(Vocabulary vocabulary, const std::vector<std::vector<uint32_t>>& idfSamples)
    : vocabulary_(std::move(vocabulary)),
      idf_(vocabulary_.size(), 0.f),
      inverted_(vocabulary_.size()) {
  std::vector<int> keyframesWithWord(vocabulary_.size(), 0);
  for (const std::vector<uint32_t>& words : idfSamples)
    for (uint32_t w : std::set<uint32_t>(words.begin(), words.end())) ++keyframesWithWord[w];
  const double n = std::max<size_t>(1, idfSamples.size());
  // A word none of the samples had is taken as rare as one that one of them had.
  for (size_t w = 0; w < idf_.size(); ++w)
    idf_[w] = static_cast<float>(std::log(n / std::max(1, keyframesWithWord[w])));
}

BagOfWords PlaceIndex::describe(const cv::Mat& descriptors) const {
  std::map<uint32_t, float> weights;
  for (uint32_t w : vocabulary_.words(descriptors)) weights[w] += idf_[w];
  double total = 0;
  for (const auto& kv : weights) total += kv.second;
  BagOfWords bag;
  if (total <= 0) return bag;
  for (const auto& [w, weight] : weights)
    if (weight > 0) bag.emplace_back(w, static_cast<float>(weight / total));
  return bag;
}

void PlaceIndex::add(KeyframeId id, BagOfWords bag) {
  remove(id);
  for (const auto& [w, weight] : bag) inverted_[w].emplace_back(id, weight);
  bags_[id] = std::move(bag);
}

void PlaceIndex::remove(KeyframeId id) {
  const auto it = bags_.find(id);
  if (it == bags_.end()) return;
  for (const auto& [w, weight] : it->second) {
    auto& list = inverted_[w];
    list.erase(
        std::remove_if(list.begin(), list.end(), [&](const auto& e) { return e.first == id; }),
        list.end());
  }
  bags_.erase(it);
}

std::vector<std::pair<KeyframeId, double>> PlaceIndex::query(const BagOfWords& bag) const {
  std::map<KeyframeId, double> scores;
  for (const auto& [w, weight] : bag)
    for (const auto& [id, theirs] : inverted_[w]) scores[id] += std::min(weight, theirs);
  return {scores.begin(), scores.end()};
}

double bagScore(const BagOfWords& a, const BagOfWords& b) {
  double score = 0;
  auto i = a.begin(), j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (i->first < j->first) {
      ++i;
    } else if (j->first < i->first) {
      ++j;
    } else {
      score += std::min(i->second, j->second);
      ++i;
      ++j;
    }
  }
  return score;
}

double PlaceIndex::score(KeyframeId a, KeyframeId b) const {
  const auto ia = bags_.find(a), ib = bags_.find(b);
  if (ia == bags_.end() || ib == bags_.end()) return 0;
  return bagScore(ia->second, ib->second);
}

}  // namespace slamdunk
