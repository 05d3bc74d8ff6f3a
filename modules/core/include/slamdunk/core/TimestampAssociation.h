#pragma once
// The TUM benchmark's association of two stamp lists (associate.py): every pair with
// |a - (b + offset)| < maxDifference is a candidate; candidates are taken greedily by increasing
// difference (ties by a, then b, as Python's tuple sort does), each stamp used once.

#include <cstddef>
#include <utility>
#include <vector>

namespace slamdunk {

/// Index pairs (i into a, j into b), sorted by (a[i], b[j]). Works on unsorted input.
std::vector<std::pair<size_t, size_t>> associateTimestamps(const std::vector<double>& a,
                                                           const std::vector<double>& b,
                                                           double maxDifference = 0.02,
                                                           double offset = 0.0);

}  // namespace slamdunk
