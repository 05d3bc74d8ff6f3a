#pragma once
// Medians of a list of numbers, for reports and robust estimates.

#include <vector>

namespace slamdunk {

/// The middle value, or the mean of the two middle values of an even count (numpy's
/// convention). NaN for an empty list.
double median(std::vector<double> values);

/// The value at index n/2 once sorted: the median of an odd count, the higher of the two middle
/// values of an even one. Cheaper (a partial sort) and always one of the values. NaN for an
/// empty list.
double upperMedian(std::vector<double> values);

}  // namespace slamdunk
