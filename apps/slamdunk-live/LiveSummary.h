#pragma once
// The end-of-run report: what the source delivered, what the tracker kept up with, and the
// accuracy against ground truth when given.

#include "LivePipeline.h"

#include <optional>
#include <string>

namespace slamdunk::live {

struct LiveAte {
  double rmse = 0, mean = 0, median = 0, max = 0;
  size_t pairs = 0;
};

struct LiveFigures {
  LiveCounters counters;
  SlamStatistics stats;
  std::vector<double> latenciesMs;  ///< per processed frame, grab to pose
  GraphMemory mapMemory;            ///< the keyframe graph's data at the end, counted directly
  double wallSeconds = 0;           ///< whole run, opening the source included
  bool interrupted = false;
  std::string sourceError;
  std::optional<size_t> recorded, recordSkipped;
  std::optional<LiveAte> ate;
};

void printLiveSummary(const LiveFigures& f, bool json);

}  // namespace slamdunk::live
