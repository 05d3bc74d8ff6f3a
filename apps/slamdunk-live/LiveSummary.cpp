#include "LiveSummary.h"

#include <slamdunk/eval/TrajectoryMetrics.h>

#include <algorithm>
#include <cstdio>

namespace slamdunk::live {

namespace {
// Timing statistics share the evaluation module's conventions (numpy's median).
double median(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).median; }
double maxOf(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).max; }
double p95(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).p95; }
double fps(size_t frames, double seconds) { return seconds > 0 ? frames / seconds : 0; }
}  // namespace

void printLiveSummary(const LiveFigures& fig, bool json) {
  const LiveResult& f = fig.result;
  const LiveCounters& c = f.counters;
  std::vector<double> trackingMs;
  f.stats.stageTimings.forEach([&](const StageTimings& t) { trackingMs.push_back(t.total); });
  const std::optional<CheckpointFigures>& cp = f.checkpoints;
  if (json) {
    std::printf(
        "{\n  \"frames_received\": %zu, \"frames_processed\": %zu, \"frames_dropped\": "
        "%zu,\n",
        c.received, c.processed, c.dropped);
    std::printf("  \"latency_ms_p50\": %.3f, \"latency_ms_p95\": %.3f, \"latency_ms_max\": %.3f,\n",
                median(f.latenciesMs), p95(f.latenciesMs), maxOf(f.latenciesMs));
    std::printf("  \"source_gap_ms_max\": %.3f, \"queue_wait_ms_max\": %.3f,\n",
                c.longestSourceGapMs, c.longestQueueWaitMs);
    std::printf(
        "  \"tracked\": %zu, \"lost\": %zu, \"tracked_depth_only\": %zu, \"keyframes\": %zu, "
        "\"optimizations\": %zu, \"loop_closures\": %zu,\n",
        c.tracked, c.lost, f.stats.trackedDepthOnly, f.stats.keyframes, f.stats.optimizations,
        f.stats.loopClosures);
    std::printf("  \"relocalizations\": %zu, \"frames_out_of_order\": %zu, \"map_kib\": %.1f,\n",
                f.stats.relocalizations, f.stats.framesOutOfOrder, f.mapMemory.total() / 1024.0);
    std::printf(
        "  \"fps_received\": %.2f, \"fps_processed\": %.2f, \"active_s\": %.3f, "
        "\"wall_s\": %.3f,\n",
        fps(c.received, c.activeSeconds), fps(c.processed, c.activeSeconds), c.activeSeconds,
        fig.wallSeconds);
    std::printf(
        "  \"ms_tracking_median\": %.3f, \"ms_tracking_p95\": %.3f, \"ms_tracking_max\": %.3f, "
        "\"ms_optimization_median\": %.3f, \"interrupted\": %s",
        median(trackingMs), p95(trackingMs), maxOf(trackingMs), median(f.stats.optimizationMs),
        f.stopRequested ? "true" : "false");
    if (cp)
      std::printf(
          ",\n  \"checkpoints\": %zu, \"checkpoint_ms_median\": %.3f, \"checkpoint_ms_max\": "
          "%.3f, \"checkpoint_snapshot_ms_median\": %.3f, \"checkpoint_snapshot_ms_max\": %.3f",
          cp->written, median(cp->totalMs), maxOf(cp->totalMs), median(cp->snapshotMs),
          maxOf(cp->snapshotMs));
    if (f.recorded)
      std::printf(",\n  \"recorded\": %zu, \"record_skipped\": %zu", *f.recorded,
                  f.recordSkipped.value_or(0));
    if (fig.ate)
      std::printf(
          ",\n  \"ate_rmse_m\": %.6f, \"ate_mean_m\": %.6f, \"ate_median_m\": %.6f, "
          "\"ate_max_m\": %.6f, \"ate_pairs\": %zu",
          fig.ate->rmse, fig.ate->mean, fig.ate->median, fig.ate->max, fig.ate->pairs);
    std::printf("\n}\n");
    return;
  }
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
  for (const auto& why : f.stats.lostReasons) std::printf("    lost because: %s\n", why.c_str());
  if (f.stats.relocalizations > 0)
    std::printf("    relocalized:  %zu times (found again in the whole map)\n",
                f.stats.relocalizations);
  if (f.stats.framesOutOfOrder > 0) {
    std::printf("  skipped:       %zu frames whose timestamp did not increase\n",
                f.stats.framesOutOfOrder);
    for (const auto& why : f.stats.outOfOrderExamples) std::printf("    %s\n", why.c_str());
  }
  std::printf(
      "  keyframes:     %zu, %zu local optimizations (ms median %.1f), %zu loop "
      "closures; map data %.1f KiB\n",
      f.stats.keyframes, f.stats.optimizations, median(f.stats.optimizationMs),
      f.stats.loopClosures, f.mapMemory.total() / 1024.0);
  std::printf(
      "  speed:         %.1f frames/s received, %.1f processed over %.2f s; tracking "
      "%.1f ms/frame (median), %.1f (p95), %.1f (max)\n",
      fps(c.received, c.activeSeconds), fps(c.processed, c.activeSeconds), c.activeSeconds,
      median(trackingMs), p95(trackingMs), maxOf(trackingMs));
  if (f.recorded)
    std::printf("  recorded:      %zu frames (%zu skipped: disk too slow)\n", *f.recorded,
                f.recordSkipped.value_or(0));
  if (cp && cp->written)
    std::printf("  checkpoints:   %zu in %s (%.0f ms median, %.0f max; graph copy %.1f ms max)\n",
                cp->written, cp->folder.c_str(), median(cp->totalMs), maxOf(cp->totalMs),
                maxOf(cp->snapshotMs));
  if (cp && !cp->error.empty()) std::printf("  checkpoint error: %s\n", cp->error.c_str());
  if (fig.ate)
    std::printf("  ATE:           rmse %.4f m, mean %.4f, median %.4f, max %.4f (%zu pairs)\n",
                fig.ate->rmse, fig.ate->mean, fig.ate->median, fig.ate->max, fig.ate->pairs);
  if (!f.sourceError.empty()) std::printf("  source error:  %s\n", f.sourceError.c_str());
  if (!f.callbackError.empty()) std::printf("  error:         %s\n", f.callbackError.c_str());
}

}  // namespace slamdunk::live
