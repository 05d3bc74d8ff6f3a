#pragma once
// slamdunk-live's end-of-run report: what the source delivered, what the tracker kept up with,
// the checkpoints, and the accuracy against ground truth when given.

#include <slamdunk/live/LiveSlam.h>

#include <optional>
#include <string>

namespace slamdunk::live {

struct LiveAte {
  double rmse = 0, mean = 0, median = 0, max = 0;
  size_t pairs = 0;
};

struct LiveFigures {
  LiveResult result;
  double wallSeconds = 0;  ///< whole run, opening the source included
  std::optional<LiveAte> ate;
};

void printLiveSummary(const LiveFigures& f, bool json);

}  // namespace slamdunk::live
