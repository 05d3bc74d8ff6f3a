#include <slamdunk/core/TimestampAssociation.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace slamdunk {

namespace {
struct Candidate {
  double diff;
  size_t i, j;
};
}  // namespace

std::vector<std::pair<size_t, size_t>> associateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double maxDifference, double offset) {
  std::vector<size_t> order(b.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return b[x] < b[y]; });
  std::vector<double> shifted(order.size());
  for (size_t k = 0; k < order.size(); ++k) shifted[k] = b[order[k]] + offset;

  // Same candidate set as associate.py's all-pairs loop, scanning only the b stamps near each a
  // (ground-truth files have tens of thousands of stamps). The window is deliberately wider
  // than maxDifference; the exact test (the script's own expression) decides.
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    auto it = std::lower_bound(shifted.begin(), shifted.end(), a[i] - 2 * maxDifference);
    for (; it != shifted.end() && *it <= a[i] + 2 * maxDifference; ++it) {
      const double diff = std::abs(a[i] - *it);
      if (diff < maxDifference) candidates.push_back({diff, i, order[it - shifted.begin()]});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [&](const Candidate& l, const Candidate& r) {
    return std::make_tuple(l.diff, a[l.i], b[l.j], l.i, l.j) <
           std::make_tuple(r.diff, a[r.i], b[r.j], r.i, r.j);
  });

  std::vector<bool> usedA(a.size(), false), usedB(b.size(), false);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (usedA[c.i] || usedB[c.j]) continue;
    usedA[c.i] = usedB[c.j] = true;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end(), [&](const auto& l, const auto& r) {
    return std::make_tuple(a[l.first], b[l.second], l.first) <
           std::make_tuple(a[r.first], b[r.second], r.first);
  });
  return pairs;
}

}  // namespace slamdunk
