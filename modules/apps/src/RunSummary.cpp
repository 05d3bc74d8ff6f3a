#include <slamdunk/apps/RunSummary.h>

#include <slamdunk/apps/SummaryFormat.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <numeric>

namespace slamdunk::apps {

using namespace summary;

long peakResidentKiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

namespace {

double perKeyframeKiB(const GraphMemory& m, size_t bytes) {
  return m.keyframes ? bytes / 1024.0 / m.keyframes : 0.0;
}
template <class F>
std::vector<double> column(const SessionLog<StageTimings>& t, F f) {
  std::vector<double> out;
  t.forEach([&](const StageTimings& s) { out.push_back(f(s)); });
  return out;
}

/// The per-frame timings, one column per stage.
struct StageColumns {
  explicit StageColumns(const SessionLog<StageTimings>& t)
      : features(column(t, [](auto& s) { return s.features; })),
        pool(column(t, [](auto& s) { return s.pool; })),
        matching(column(t, [](auto& s) { return s.matching; })),
        ransac(column(t, [](auto& s) { return s.ransac; })),
        total(column(t, [](auto& s) { return s.total; })),
        poolWait(column(t, [](auto& s) { return s.poolWait; })) {}
  std::vector<double> features, pool, matching, ransac, total, poolWait;
  /// Frames that waited for Local Mapping's hand-over (more than 0.1 ms).
  size_t waits() const {
    return std::count_if(poolWait.begin(), poolWait.end(), [](double w) { return w > 0.1; });
  }
};

size_t largestPool(const PoolPreparationStats& prep) {
  size_t largest = 0;
  for (size_t n : prep.windowSizes) largest = std::max(largest, n);
  return largest;
}

double framesPerSecond(const RunFigures& f) {
  return f.wallSeconds > 0 ? f.stats.frames / f.wallSeconds : 0;
}

void printJsonSummary(const RunFigures& f) {
  const SlamStatistics& s = f.stats;
  const StageColumns ms(s.stageTimings);
  const PoolPreparationStats& prep = s.poolPreparation;
  const GraphMemory& m = f.mapMemory;
  Json j;
  j["frames"] = s.frames;
  j["tracked"] = s.tracked;
  j["lost"] = s.lost;
  j["edges"] = f.edges;
  addSlamCounts(j, s);
  addMs(j, ms.features, {{"ms_features_median", Stat::median}});
  addMs(j, ms.pool, {{"ms_pool_median", Stat::median}});
  addMs(j, ms.matching, {{"ms_matching_median", Stat::median}});
  addMs(j, ms.ransac, {{"ms_ransac_median", Stat::median}});
  addMs(j, ms.total,
        {{"ms_tracking_median", Stat::median},
         {"ms_tracking_mean", Stat::mean},
         {"ms_tracking_p95", Stat::p95},
         {"ms_tracking_p99", Stat::p99},
         {"ms_tracking_max", Stat::max}});
  addMs(j, f.decodeMs, {{"ms_decode_median", Stat::median}});
  j["pool_windows"] = prep.windowMs.size();
  j["pool_features_max"] = largestPool(prep);
  addMs(j, prep.windowMs,
        {{"ms_pool_preparation_median", Stat::median}, {"ms_pool_preparation_max", Stat::max}});
  addMs(j, prep.keyframeMs, {{"ms_keyframe_index_median", Stat::median}});
  j["pool_waits"] = ms.waits();
  j["ms_pool_wait_total"] = rounded(sum(ms.poolWait), 3);
  addMs(j, ms.poolWait, {{"ms_pool_wait_max", Stat::max}});
  addMs(j, s.optimizationMs,
        {{"ms_optimization_median", Stat::median}, {"ms_optimization_max", Stat::max}});
  j["optimizer_share"] = rounded(optimizerShare(s.optimizationMs, f.wallSeconds), 3);
  j["optimization_max_translation_m"] = rounded(s.maxOptimizationTranslation, 6);
  j["optimization_max_rotation_deg"] = rounded(s.maxOptimizationRotationDeg, 4);
  j["first_tracked_frame"] = f.firstTrackedFrame;
  j["camera_rolling_shutter_ms"] = rounded(s.rollingShutterMs, 2);
  j["camera_keypoint_pixel_sigma"] = rounded(s.keypointNoise.pixelSigma, 3);
  j["camera_keypoint_depth_sigma"] = rounded(s.keypointNoise.depthSigmaQuadratic, 5);
  j["map_kib_features"] = rounded(m.features / 1024.0, 1);
  j["map_kib_depth_small"] = rounded(m.depthSmall / 1024.0, 1);
  j["map_kib_edges"] = rounded(m.edges / 1024.0, 1);
  j["map_kib_images"] = rounded(m.images / 1024.0, 1);
  j["map_kib_per_keyframe"] = rounded(perKeyframeKiB(m, m.withoutImages()), 1);
  j["map_kib_per_keyframe_with_images"] = rounded(perKeyframeKiB(m, m.total()), 1);
  j["fps"] = rounded(framesPerSecond(f), 2);
  j["wall_s"] = rounded(f.wallSeconds, 3);
  j["peak_rss_mib"] = rounded(f.peakRssKiB / 1024.0, 1);
  if (f.ate) addAte(j, *f.ate);
  printJson(j);
}

void printTextSummary(const RunFigures& f) {
  const SlamStatistics& s = f.stats;
  const StageColumns ms(s.stageTimings);
  const PoolPreparationStats& prep = s.poolPreparation;
  std::printf("slamdunk-rawlog summary\n");
  std::printf("  frames:          %zu (tracked %zu, lost %zu)\n", s.frames, s.tracked, s.lost);
  if (s.trackedDepthOnly > 0)
    std::printf("    by depth alone: %zu (the features did not register them)\n",
                s.trackedDepthOnly);
  printTrackingProblems(s, 19);
  std::printf("  first tracked:   frame %ld\n", f.firstTrackedFrame);
  std::printf("  keyframes:       %zu, graph edges %zu", s.keyframes, f.edges);
  if (s.keyframesCulled > 0) std::printf(" (%zu more culled as redundant)", s.keyframesCulled);
  std::printf("\n");
  const LoopClosingStatistics& places = s.placeLoops;
  std::printf("  loop closures:   %zu inferred, %zu by place recognition", s.loopClosures,
              places.loops);
  if (!places.detectionMs.empty())
    std::printf(
        " (%zu candidates verified, %zu of them refused as too far for drift, look-up ms "
        "median %.1f max %.1f)",
        places.candidatesVerified, places.candidatesRefused, median(places.detectionMs),
        maxOf(places.detectionMs));
  if (places.loops > 0)
    std::printf(", corrected by up to %.3f m in %.0f ms at most", places.maxCorrection,
                maxOf(places.correctionMs));
  std::printf("\n");
  if (s.componentsStarted > 0)
    std::printf(
        "  map components:  %zu started (not relocalized in the loaded map), %zu joined by place "
        "recognition, %zu joins refused (the map's keyframes saw otherwise)\n",
        s.componentsStarted, places.joins, places.joinsRefused);
  std::printf(
      "  camera learned:  rolling shutter %.1f ms, keypoints %.2f px, depth %.4f m at 1 m\n",
      s.rollingShutterMs, s.keypointNoise.pixelSigma, s.keypointNoise.depthSigmaQuadratic);
  std::printf(
      "  optimizations:   %zu, ms median %.1f max %.1f, %.0f %% of the run; largest pose "
      "change %.4f m %.3f deg\n",
      s.optimizations, median(s.optimizationMs), maxOf(s.optimizationMs),
      100 * optimizerShare(s.optimizationMs, f.wallSeconds), s.maxOptimizationTranslation,
      s.maxOptimizationRotationDeg);
  std::printf("  ms per frame     median   mean\n");
  const auto row = [](const char* stage, const std::vector<double>& v, const char* more = "") {
    std::printf("    %-14s %6.2f %6.2f%s\n", stage, median(v), mean(v), more);
  };
  row("decode wait", f.decodeMs);
  row("features", ms.features);
  row("pool update", ms.pool);
  row("matching", ms.matching);
  row("RANSAC", ms.ransac);
  char tails[96];
  std::snprintf(tails, sizeof tails, "  (p95 %.2f, p99 %.2f, max %.2f)", p95(ms.total),
                p99(ms.total), maxOf(ms.total));
  row("tracking total", ms.total, tails);
  std::printf(
      "  pool preparation: %zu windows (up to %zu features), ms median %.1f max %.1f; new "
      "keyframe's index ms median %.1f\n",
      prep.windowMs.size(), largestPool(prep), median(prep.windowMs), maxOf(prep.windowMs),
      median(prep.keyframeMs));
  if (const size_t waits = ms.waits(); waits > 0)
    std::printf("    hand-over waits: %zu frames, %.1f ms in all, max %.1f\n", waits,
                sum(ms.poolWait), maxOf(ms.poolWait));
  std::printf("  speed:           %.1f frames/s over %.2f s (whole app)\n", framesPerSecond(f),
              f.wallSeconds);
  std::printf("  peak memory:     %.1f MiB\n", f.peakRssKiB / 1024.0);
  const GraphMemory& m = f.mapMemory;
  std::printf(
      "  map data:        %.1f KiB per keyframe (features %.1f, small depth %.1f, edges %.1f); "
      "%.1f with images\n",
      perKeyframeKiB(m, m.withoutImages()), perKeyframeKiB(m, m.features),
      perKeyframeKiB(m, m.depthSmall), perKeyframeKiB(m, m.edges), perKeyframeKiB(m, m.total()));
  if (f.ate) printAteLine(*f.ate, 19, true);
}

}  // namespace

void printRunSummary(const RunFigures& f, bool json) {
  json ? printJsonSummary(f) : printTextSummary(f);
}

}  // namespace slamdunk::apps
