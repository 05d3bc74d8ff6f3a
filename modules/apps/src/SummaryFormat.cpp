#include <slamdunk/apps/SummaryFormat.h>

#include <slamdunk/eval/TrajectoryMetrics.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

namespace slamdunk::apps {

std::optional<AteFigures> evaluateAte(const Trajectory& groundTruth, const Trajectory& estimate) {
  if (estimate.size() < 3) return std::nullopt;
  const auto ev = eval::TrajectoryMetrics::evaluate(groundTruth, estimate);
  const eval::ErrorStatistics& s = ev.ate.stats;
  return AteFigures{s.rmse, s.mean, s.median, s.max, ev.pairs, ev.unmatchedEstimatePoses};
}

namespace summary {

double median(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).median; }
double mean(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).mean; }
double maxOf(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).max; }
double p95(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).p95; }
double p99(const std::vector<double>& v) { return eval::ErrorStatistics::compute(v).p99; }
double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }
double optimizerShare(const std::vector<double>& optimizationMs, double seconds) {
  return seconds > 0 ? sum(optimizationMs) / (1000 * seconds) : 0.0;
}

double rounded(double x, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(x * scale) / scale;
}

void addMs(Json& json, const std::vector<double>& ms,
           std::initializer_list<std::pair<const char*, Stat>> keys) {
  const eval::ErrorStatistics s = eval::ErrorStatistics::compute(ms);
  for (const auto& [key, stat] : keys) {
    const double values[] = {s.median, s.mean, s.p95, s.p99, s.max};
    json[key] = rounded(values[static_cast<int>(stat)], 3);
  }
}

void addSlamCounts(Json& json, const SlamStatistics& s) {
  json["tracked_depth_only"] = s.trackedDepthOnly;
  json["keyframes"] = s.keyframes;
  json["keyframes_culled"] = s.keyframesCulled;
  json["optimizations"] = s.optimizations;
  json["loop_closures"] = s.loopClosures;
  json["place_loops"] = s.placeLoops.loops;
  json["place_candidates_verified"] = s.placeLoops.candidatesVerified;
  json["place_candidates_refused"] = s.placeLoops.candidatesRefused;
  addMs(json, s.placeLoops.detectionMs,
        {{"place_lookup_ms_p50", Stat::median}, {"place_lookup_ms_max", Stat::max}});
  addMs(json, s.placeLoops.correctionMs, {{"loop_correction_ms_max", Stat::max}});
  json["loop_correction_max_m"] = rounded(s.placeLoops.maxCorrection, 4);
  json["components_started"] = s.componentsStarted;
  json["components_joined"] = s.placeLoops.joins;
  json["component_joins_refused"] = s.placeLoops.joinsRefused;
  json["relocalizations"] = s.relocalizations;
  json["frames_outside_map"] = s.framesOutsideMap;
  json["frames_out_of_order"] = s.framesOutOfOrder;
}

void addAte(Json& json, const AteFigures& ate) {
  json["ate_rmse_m"] = rounded(ate.rmse, 6);
  json["ate_mean_m"] = rounded(ate.mean, 6);
  json["ate_median_m"] = rounded(ate.median, 6);
  json["ate_max_m"] = rounded(ate.max, 6);
  json["ate_pairs"] = ate.pairs;
}

void printJson(const Json& json) { std::printf("%s\n", json.dump(2).c_str()); }

void printAteLine(const AteFigures& ate, int width, bool unmatched) {
  std::printf("%-*s rmse %.4f m, mean %.4f, median %.4f, max %.4f (%zu pairs", width - 1,
              "  ATE:", ate.rmse, ate.mean, ate.median, ate.max, ate.pairs);
  if (unmatched) std::printf(", %zu estimated poses without ground truth", ate.unmatched);
  std::printf(")\n");
}

void printTrackingProblems(const SlamStatistics& s, int width) {
  const auto line = [width](const char* label, const std::string& text) {
    std::printf("%-*s %s\n", width - 1, label, text.c_str());
  };
  for (const auto& why : s.lostReasons) line("    lost because:", why);
  if (s.relocalizations > 0)
    line("  relocalized:",
         std::to_string(s.relocalizations) + " times (found again in the whole map)");
  if (s.framesOutsideMap > 0)
    line("  outside the map:", std::to_string(s.framesOutsideMap) +
                                   " tracked frames whose view the map covers too little");
  if (s.framesOutOfOrder > 0) {
    line("  skipped:",
         std::to_string(s.framesOutOfOrder) + " frames whose timestamp did not increase");
    for (const auto& why : s.outOfOrderExamples) std::printf("    %s\n", why.c_str());
  }
}

}  // namespace summary
}  // namespace slamdunk::apps
