#pragma once
// The end-of-run report of an offline run (slamdunk-rawlog): counts, per-stage timings, speed,
// memory, accuracy; as text or as JSON (keys documented in docs/tools.md).

#include <slamdunk/apps/AteFigures.h>
#include <slamdunk/slam/SlamSystem.h>

#include <optional>
#include <vector>

namespace slamdunk::apps {

struct RunFigures {
  SlamStatistics stats;
  size_t edges = 0;
  double wallSeconds = 0;        ///< whole run: reading, decoding, tracking, optimizing
  std::vector<double> decodeMs;  ///< per frame: waiting for it (read, prepared ahead)
  long peakRssKiB = 0;
  GraphMemory mapMemory;        ///< the keyframe graph's data at the end, counted directly
  long firstTrackedFrame = -1;  ///< index of the first frame not lost (relocalization delay)
  std::optional<AteFigures> ate;
};

/// Peak resident memory of this process so far.
long peakResidentKiB();
/// Prints the report on stdout.
void printRunSummary(const RunFigures& f, bool json);

}  // namespace slamdunk::apps
