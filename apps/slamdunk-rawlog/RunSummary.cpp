#include "RunSummary.h"

#include <slamdunk/eval/TrajectoryMetrics.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <deque>
#include <numeric>

namespace slamdunk {

long peakResidentKiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

namespace {
// Timing statistics share the evaluation module's conventions (numpy's median).
double median(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).median; }
double mean(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).mean; }
double maxOf(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).max; }
double p95(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).p95; }
double p99(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).p99; }
double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }
double perKeyframeKiB(const GraphMemory& m, size_t bytes) {
  return m.keyframes ? bytes / 1024.0 / m.keyframes : 0.0;
}
template <class F>
std::vector<double> column(const SessionLog<StageTimings>& t, F f) {
  std::vector<double> out;
  t.forEach([&](const StageTimings& s) { out.push_back(f(s)); });
  return out;
}
}  // namespace

void printRunSummary(const RunFigures& f, bool json) {
  const auto& s = f.stats;
  const auto feat = column(s.stageTimings, [](auto& t) { return t.features; });
  const auto pool = column(s.stageTimings, [](auto& t) { return t.pool; });
  const auto match = column(s.stageTimings, [](auto& t) { return t.matching; });
  const auto ransac = column(s.stageTimings, [](auto& t) { return t.ransac; });
  const auto total = column(s.stageTimings, [](auto& t) { return t.total; });
  const auto wait = column(s.stageTimings, [](auto& t) { return t.poolWait; });
  const size_t waits = std::count_if(wait.begin(), wait.end(), [](double w) { return w > 0.1; });
  const PoolPreparationStats& prep = s.poolPreparation;
  size_t largestPool = 0;
  for (size_t n : prep.windowSizes) largestPool = std::max(largestPool, n);
  const double fps = f.wallSeconds > 0 ? s.frames / f.wallSeconds : 0;
  if (json) {
    std::printf(
        "{\n  \"frames\": %zu, \"tracked\": %zu, \"lost\": %zu, \"keyframes\": %zu, "
        "\"tracked_depth_only\": %zu,\n",
        s.frames, s.tracked, s.lost, s.keyframes, s.trackedDepthOnly);
    std::printf("  \"edges\": %zu, \"optimizations\": %zu, \"loop_closures\": %zu,\n", f.edges,
                s.optimizations, s.loopClosures);
    std::printf("  \"relocalizations\": %zu, \"frames_out_of_order\": %zu,\n", s.relocalizations,
                s.framesOutOfOrder);
    std::printf(
        "  \"ms_features_median\": %.3f, \"ms_pool_median\": %.3f, "
        "\"ms_matching_median\": %.3f, \"ms_ransac_median\": %.3f,\n",
        median(feat), median(pool), median(match), median(ransac));
    std::printf(
        "  \"ms_tracking_median\": %.3f, \"ms_tracking_mean\": %.3f, "
        "\"ms_decode_median\": %.3f,\n",
        median(total), mean(total), median(f.decodeMs));
    std::printf(
        "  \"ms_tracking_p95\": %.3f, \"ms_tracking_p99\": %.3f, \"ms_tracking_max\": %.3f,\n",
        p95(total), p99(total), maxOf(total));
    std::printf(
        "  \"pool_windows\": %zu, \"pool_features_max\": %zu, "
        "\"ms_pool_preparation_median\": %.3f, \"ms_pool_preparation_max\": %.3f, "
        "\"ms_keyframe_index_median\": %.3f,\n",
        prep.windowMs.size(), largestPool, median(prep.windowMs), maxOf(prep.windowMs),
        median(prep.keyframeMs));
    std::printf(
        "  \"pool_waits\": %zu, \"ms_pool_wait_total\": %.3f, \"ms_pool_wait_max\": %.3f,\n", waits,
        sum(wait), maxOf(wait));
    std::printf("  \"ms_optimization_median\": %.3f, \"ms_optimization_max\": %.3f,\n",
                median(s.optimizationMs), maxOf(s.optimizationMs));
    std::printf(
        "  \"optimization_max_translation_m\": %.6f, \"optimization_max_rotation_deg\": "
        "%.4f,\n",
        s.maxOptimizationTranslation, s.maxOptimizationRotationDeg);
    std::printf("  \"first_tracked_frame\": %ld,\n", f.firstTrackedFrame);
    std::printf(
        "  \"camera_rolling_shutter_ms\": %.2f, \"camera_keypoint_pixel_sigma\": %.3f, "
        "\"camera_keypoint_depth_sigma\": %.5f,\n",
        s.rollingShutterMs, s.keypointNoise.pixelSigma, s.keypointNoise.depthSigmaQuadratic);
    const GraphMemory& m = f.mapMemory;
    std::printf(
        "  \"map_kib_features\": %.1f, \"map_kib_depth_small\": %.1f, \"map_kib_edges\": %.1f, "
        "\"map_kib_images\": %.1f, \"map_kib_per_keyframe\": %.1f, "
        "\"map_kib_per_keyframe_with_images\": %.1f,\n",
        m.features / 1024.0, m.depthSmall / 1024.0, m.edges / 1024.0, m.images / 1024.0,
        perKeyframeKiB(m, m.withoutImages()), perKeyframeKiB(m, m.total()));
    std::printf("  \"fps\": %.2f, \"wall_s\": %.3f, \"peak_rss_mib\": %.1f", fps, f.wallSeconds,
                f.peakRssKiB / 1024.0);
    if (f.ate)
      std::printf(
          ",\n  \"ate_rmse_m\": %.6f, \"ate_mean_m\": %.6f, \"ate_median_m\": %.6f, "
          "\"ate_max_m\": %.6f, \"ate_pairs\": %zu",
          f.ate->rmse, f.ate->mean, f.ate->median, f.ate->max, f.ate->pairs);
    std::printf("\n}\n");
    return;
  }
  std::printf("slamdunk-rawlog summary\n");
  std::printf("  frames:          %zu (tracked %zu, lost %zu)\n", s.frames, s.tracked, s.lost);
  if (s.trackedDepthOnly > 0)
    std::printf("    by depth alone: %zu (the features did not register them)\n",
                s.trackedDepthOnly);
  for (const auto& why : s.lostReasons) std::printf("    lost because:  %s\n", why.c_str());
  if (s.relocalizations > 0)
    std::printf("  relocalized:     %zu times (found again in the whole map)\n", s.relocalizations);
  if (s.framesOutOfOrder > 0) {
    std::printf("  skipped:         %zu frames whose timestamp did not increase\n",
                s.framesOutOfOrder);
    for (const auto& why : s.outOfOrderExamples) std::printf("    %s\n", why.c_str());
  }
  std::printf("  first tracked:   frame %ld\n", f.firstTrackedFrame);
  std::printf("  keyframes:       %zu, graph edges %zu\n", s.keyframes, f.edges);
  std::printf("  loop closures:   %zu inferred\n", s.loopClosures);
  std::printf(
      "  camera learned:  rolling shutter %.1f ms, keypoints %.2f px, depth %.4f m at 1 m\n",
      s.rollingShutterMs, s.keypointNoise.pixelSigma, s.keypointNoise.depthSigmaQuadratic);
  std::printf(
      "  optimizations:   %zu, ms median %.1f max %.1f; largest pose change %.4f m "
      "%.3f deg\n",
      s.optimizations, median(s.optimizationMs), maxOf(s.optimizationMs),
      s.maxOptimizationTranslation, s.maxOptimizationRotationDeg);
  std::printf("  ms per frame     median   mean\n");
  std::printf("    decode wait    %6.2f %6.2f\n", median(f.decodeMs), mean(f.decodeMs));
  std::printf("    features       %6.2f %6.2f\n", median(feat), mean(feat));
  std::printf("    pool update    %6.2f %6.2f\n", median(pool), mean(pool));
  std::printf("    matching       %6.2f %6.2f\n", median(match), mean(match));
  std::printf("    RANSAC         %6.2f %6.2f\n", median(ransac), mean(ransac));
  std::printf("    tracking total %6.2f %6.2f  (p95 %.2f, p99 %.2f, max %.2f)\n", median(total),
              mean(total), p95(total), p99(total), maxOf(total));
  std::printf(
      "  pool preparation: %zu windows (up to %zu features), ms median %.1f max %.1f; new "
      "keyframe's index ms median %.1f\n",
      prep.windowMs.size(), largestPool, median(prep.windowMs), maxOf(prep.windowMs),
      median(prep.keyframeMs));
  if (waits > 0)
    std::printf("    hand-over waits: %zu frames, %.1f ms in all, max %.1f\n", waits, sum(wait),
                maxOf(wait));
  std::printf("  speed:           %.1f frames/s over %.2f s (whole app)\n", fps, f.wallSeconds);
  std::printf("  peak memory:     %.1f MiB\n", f.peakRssKiB / 1024.0);
  const GraphMemory& m = f.mapMemory;
  std::printf(
      "  map data:        %.1f KiB per keyframe (features %.1f, small depth %.1f, edges %.1f); "
      "%.1f with images\n",
      perKeyframeKiB(m, m.withoutImages()), perKeyframeKiB(m, m.features),
      perKeyframeKiB(m, m.depthSmall), perKeyframeKiB(m, m.edges), perKeyframeKiB(m, m.total()));
  if (f.ate)
    std::printf(
        "  ATE:             rmse %.4f m, mean %.4f, median %.4f, max %.4f (%zu pairs, %zu "
        "estimated poses without ground truth)\n",
        f.ate->rmse, f.ate->mean, f.ate->median, f.ate->max, f.ate->pairs, f.ate->unmatched);
}

}  // namespace slamdunk
