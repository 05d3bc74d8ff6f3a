#include <slamdunk/apps/LiveSummary.h>

#include <slamdunk/apps/SummaryFormat.h>

#include <cstdio>

namespace slamdunk::apps {

using namespace summary;
using live::CheckpointFigures;
using live::LiveCounters;
using live::LiveResult;

namespace {

double fps(size_t frames, double seconds) { return seconds > 0 ? frames / seconds : 0; }

std::vector<double> trackingMs(const SlamStatistics& s) {
  std::vector<double> ms;
  s.stageTimings.forEach([&](const StageTimings& t) { ms.push_back(t.total); });
  return ms;
}

void printJsonSummary(const LiveFigures& fig) {
  const LiveResult& f = fig.result;
  const LiveCounters& c = f.counters;
  const std::vector<double> tracking = trackingMs(f.stats);
  Json j;
  j["frames_received"] = c.received;
  j["frames_processed"] = c.processed;
  j["frames_dropped"] = c.dropped;
  addMs(j, f.latenciesMs,
        {{"latency_ms_p50", Stat::median},
         {"latency_ms_p95", Stat::p95},
         {"latency_ms_max", Stat::max}});
  j["source_gap_ms_max"] = rounded(c.longestSourceGapMs, 3);
  j["queue_wait_ms_max"] = rounded(c.longestQueueWaitMs, 3);
  j["tracked"] = c.tracked;
  j["lost"] = c.lost;
  addSlamCounts(j, f.stats);
  j["map_kib"] = rounded(f.mapMemory.total() / 1024.0, 1);
  j["fps_received"] = rounded(fps(c.received, c.activeSeconds), 2);
  j["fps_processed"] = rounded(fps(c.processed, c.activeSeconds), 2);
  j["active_s"] = rounded(c.activeSeconds, 3);
  j["wall_s"] = rounded(fig.wallSeconds, 3);
  addMs(j, tracking,
        {{"ms_tracking_median", Stat::median},
         {"ms_tracking_p95", Stat::p95},
         {"ms_tracking_max", Stat::max}});
  addMs(j, f.stats.optimizationMs, {{"ms_optimization_median", Stat::median}});
  j["optimizer_share"] = rounded(optimizerShare(f.stats.optimizationMs, c.activeSeconds), 3);
  j["interrupted"] = f.stopRequested;
  if (const std::optional<CheckpointFigures>& cp = f.checkpoints) {
    j["checkpoints"] = cp->written;
    addMs(j, cp->totalMs,
          {{"checkpoint_ms_median", Stat::median}, {"checkpoint_ms_max", Stat::max}});
    addMs(j, cp->snapshotMs,
          {{"checkpoint_snapshot_ms_median", Stat::median},
           {"checkpoint_snapshot_ms_max", Stat::max}});
  }
  if (f.recorded) {
    j["recorded"] = *f.recorded;
    j["record_skipped"] = f.recordSkipped.value_or(0);
  }
  if (fig.ate) addAte(j, *fig.ate);
  printJson(j);
}

void printTextSummary(const LiveFigures& fig) {
  const LiveResult& f = fig.result;
  const LiveCounters& c = f.counters;
  const std::vector<double> tracking = trackingMs(f.stats);
  const std::optional<CheckpointFigures>& cp = f.checkpoints;
  std::printf("slamdunk-live summary%s\n", f.stopRequested ? " (interrupted)" : "");
  std::printf("  frames:        %zu received, %zu processed, %zu dropped (tracker behind)\n",
              c.received, c.processed, c.dropped);
  std::printf("  latency:       grab to pose %.1f ms median, %.1f p95, %.1f max\n",
              median(f.latenciesMs), p95(f.latenciesMs), maxOf(f.latenciesMs));
  std::printf(
      "  delays:        longest gap between frames from the source %.1f ms, longest wait "
      "for the tracker %.1f ms\n",
      c.longestSourceGapMs, c.longestQueueWaitMs);
  std::printf("  tracking:      %zu tracked (%zu by depth alone), %zu lost\n", c.tracked,
              f.stats.trackedDepthOnly, c.lost);
  printTrackingProblems(f.stats, 17);
  std::printf(
      "  keyframes:     %zu, %zu local optimizations (ms median %.1f, busy %.0f %% of the "
      "session, on their own thread), %zu loop closures; map data %.1f KiB\n",
      f.stats.keyframes, f.stats.optimizations, median(f.stats.optimizationMs),
      100 * optimizerShare(f.stats.optimizationMs, c.activeSeconds), f.stats.loopClosures,
      f.mapMemory.total() / 1024.0);
  std::printf(
      "  speed:         %.1f frames/s received, %.1f processed over %.2f s; tracking "
      "%.1f ms/frame (median), %.1f (p95), %.1f (max)\n",
      fps(c.received, c.activeSeconds), fps(c.processed, c.activeSeconds), c.activeSeconds,
      median(tracking), p95(tracking), maxOf(tracking));
  if (f.recorded)
    std::printf("  recorded:      %zu frames (%zu skipped: disk too slow)\n", *f.recorded,
                f.recordSkipped.value_or(0));
  if (cp && cp->written)
    std::printf("  checkpoints:   %zu in %s (%.0f ms median, %.0f max; graph copy %.1f ms max)\n",
                cp->written, cp->folder.c_str(), median(cp->totalMs), maxOf(cp->totalMs),
                maxOf(cp->snapshotMs));
  if (cp && !cp->error.empty()) std::printf("  checkpoint error: %s\n", cp->error.c_str());
  if (fig.ate) printAteLine(*fig.ate, 17, false);
  if (!f.sourceError.empty()) std::printf("  source error:  %s\n", f.sourceError.c_str());
  if (!f.callbackError.empty()) std::printf("  error:         %s\n", f.callbackError.c_str());
}

}  // namespace

void printLiveSummary(const LiveFigures& f, bool json) {
  json ? printJsonSummary(f) : printTextSummary(f);
}

}  // namespace slamdunk::apps
