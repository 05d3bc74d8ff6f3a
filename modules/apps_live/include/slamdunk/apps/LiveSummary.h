#pragma once
// The end-of-run report of a live session (slamdunk-live): what the source delivered, what the
// tracker kept up with, the checkpoints, and the accuracy against ground truth when given; as
// text or as JSON (keys documented in docs/tools.md).

#include <slamdunk/apps/AteFigures.h>
#include <slamdunk/live/LiveSlam.h>

#include <optional>

namespace slamdunk::apps {

struct LiveFigures {
  live::LiveResult result;
  double wallSeconds = 0;  ///< whole run, opening the source included
  std::optional<AteFigures> ate;
};

/// Prints the report on stdout.
void printLiveSummary(const LiveFigures& f, bool json);

}  // namespace slamdunk::apps
