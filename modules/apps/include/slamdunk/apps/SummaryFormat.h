#pragma once
// What the offline and live summaries share: timing statistics, the ATE keys, the lines about
// lost and skipped frames. For the two summaries (RunSummary, LiveSummary), not a public API.

#include <slamdunk/apps/AteFigures.h>
#include <slamdunk/slam/SlamSystem.h>

#include <nlohmann/json.hpp>

#include <initializer_list>
#include <utility>
#include <vector>

namespace slamdunk::apps::summary {

using Json = nlohmann::ordered_json;  // keys in the order written, as readers have seen them

// Timing statistics share the evaluation module's conventions (numpy's median).
double median(const std::vector<double>& v);
double mean(const std::vector<double>& v);
double maxOf(const std::vector<double>& v);
double p95(const std::vector<double>& v);
double p99(const std::vector<double>& v);
double sum(const std::vector<double>& v);
/// The share of `seconds` the local optimizations (`optimizationMs`) took: inline (offline) they
/// hold tracking up for it; on their own thread (live) it is one core's share.
double optimizerShare(const std::vector<double>& optimizationMs, double seconds);

/// `x` to `decimals` places: the precision each figure is meaningful to, as JSON prints it.
double rounded(double x, int decimals);

enum class Stat { median, mean, p95, p99, max };
/// Adds a statistic of `ms` (milliseconds, to 3 decimals) under each key, e.g.
/// addMs(json, latencies, {{"latency_ms_p50", Stat::median}, {"latency_ms_max", Stat::max}}).
void addMs(Json& json, const std::vector<double>& ms,
           std::initializer_list<std::pair<const char*, Stat>> keys);

/// Adds what both apps count of the map and the frames: tracked_depth_only, keyframes,
/// optimizations, loop_closures, relocalizations, frames_out_of_order, and place recognition's
/// place_loops, place_candidates_verified / _refused, place_lookup_ms_p50 / _max,
/// loop_correction_ms_max, loop_correction_max_m, and the map's components_started,
/// components_joined and component_joins_refused.
void addSlamCounts(Json& json, const SlamStatistics& s);
/// Adds ate_rmse_m, ate_mean_m, ate_median_m, ate_max_m and ate_pairs.
void addAte(Json& json, const AteFigures& ate);
/// Prints `json` (two-space indents, `"key": value`) and a newline to stdout.
void printJson(const Json& json);

/// The summary's ATE line, its figures starting at column `width`; `unmatched`: with the count
/// of estimated poses that had no ground truth.
void printAteLine(const AteFigures& ate, int width, bool unmatched);

/// The summary lines on why frames were lost, relocalizations and frames skipped for their
/// timestamp; values start at column `width`.
void printTrackingProblems(const SlamStatistics& s, int width);

}  // namespace slamdunk::apps::summary
