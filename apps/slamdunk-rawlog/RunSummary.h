#pragma once
// The end-of-run report of the offline app: counts, per-stage timings, speed, memory.

#include <slamdunk/slam/SlamSystem.h>

#include <optional>
#include <string>

namespace slamdunk {

struct AteFigures {
  double rmse = 0, mean = 0, median = 0, max = 0;
  size_t pairs = 0, unmatched = 0;
};

struct RunFigures {
  SlamStatistics stats;
  size_t edges = 0;
  double wallSeconds = 0;        ///< whole run: reading, decoding, tracking, optimizing
  std::vector<double> decodeMs;  ///< per frame: rawlog read + image decode
  long peakRssKiB = 0;
  GraphMemory mapMemory;        ///< the keyframe graph's data at the end, counted directly
  long firstTrackedFrame = -1;  ///< index of the first frame not lost (relocalization delay)
  std::optional<AteFigures> ate;
};

/// Peak resident memory of this process so far.
long peakResidentKiB();
void printRunSummary(const RunFigures& f, bool json);

}  // namespace slamdunk
