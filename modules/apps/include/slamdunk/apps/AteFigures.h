#pragma once
// The accuracy figures both apps report against a ground truth (TUM file).

#include <slamdunk/core/TumTrajectory.h>

#include <optional>

namespace slamdunk::apps {

struct AteFigures {
  double rmse = 0, mean = 0, median = 0, max = 0;  ///< metres
  size_t pairs = 0;                                ///< estimated poses matched in time
  size_t unmatched = 0;                            ///< estimated poses without ground truth
};

/// The absolute trajectory error of `estimate` (aligned to `groundTruth`); none with fewer than
/// three estimated poses, where an alignment means nothing.
std::optional<AteFigures> evaluateAte(const Trajectory& groundTruth, const Trajectory& estimate);

}  // namespace slamdunk::apps
