#pragma once
// The TUM benchmark's association of two stamp lists (associate.py): candidate pairs with
// |a - b| < maxDifference, taken greedily by smallest difference, one-to-one.

#include <cstddef>
#include <utility>
#include <vector>

namespace slamdunk {

/// Index pairs (i into a, j into b), sorted by a's index.
std::vector<std::pair<size_t, size_t>> associateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double maxDifference = 0.02);

}  // namespace slamdunk
