#include <slamdunk/core/TimestampAssociation.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace slamdunk {

std::vector<std::pair<size_t, size_t>> associateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double maxDifference) {
  // Candidates come from a sorted copy of b, so each a only looks at the stamps in its window
  // instead of all of b (sequences have tens of thousands of ground-truth stamps).
  std::vector<size_t> order(b.size());
  for (size_t j = 0; j < b.size(); ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return b[x] < b[y]; });
  std::vector<double> sortedB(b.size());
  for (size_t k = 0; k < order.size(); ++k) sortedB[k] = b[order[k]];

  std::vector<std::tuple<double, size_t, size_t>> candidates;  // (|dt|, i, j)
  for (size_t i = 0; i < a.size(); ++i) {
    auto it = std::lower_bound(sortedB.begin(), sortedB.end(), a[i] - maxDifference);
    for (; it != sortedB.end() && *it <= a[i] + maxDifference; ++it) {
      const double d = std::abs(a[i] - *it);
      if (d < maxDifference) candidates.emplace_back(d, i, order[it - sortedB.begin()]);
    }
  }
  // Ties broken by indices so the result never depends on sort internals.
  std::sort(candidates.begin(), candidates.end());

  std::vector<bool> usedA(a.size(), false), usedB(b.size(), false);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const auto& [d, i, j] : candidates) {
    if (usedA[i] || usedB[j]) continue;
    usedA[i] = usedB[j] = true;
    pairs.emplace_back(i, j);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace slamdunk
