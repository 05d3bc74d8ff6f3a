// bench-pool: what the feature pool's index costs and how well it matches. Runs SlamDunk over a
// rawlog to get a map and each frame's pose, then, at evenly spaced query frames, builds the pool
// of the active window around the frame's pose with each candidate index and matches the frame's
// features against it. Matches are compared with those of an exact (brute-force) index: recall
// is the share of the exact ratio-test matches a candidate finds, precision the share of its
// matches the exact search agrees with.

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/slam/SlamSystem.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <set>

using namespace slamdunk;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Candidate {
  std::string name;
  FeaturePoolOptions options;
  bool perKeyframe = false;  ///< one part per keyframe (built once when the keyframe is made)
};

struct Figures {
  std::vector<double> buildMs, matchMs, recall, precision, features;
};

using MatchSet = std::set<std::pair<uint32_t, std::pair<KeyframeId, uint32_t>>>;
MatchSet matchSet(const FeaturePool& pool, const std::vector<PoolMatch>& matches) {
  MatchSet s;
  for (const PoolMatch& m : matches) {
    const PoolFeature& f = pool.feature(m.pool);
    s.insert({m.query, {f.keyframe, f.index}});
  }
  return s;
}

std::string stats(const std::vector<double>& v, const char* format) {
  const auto s = eval::ErrorStatistics::compute(v);
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, s.median, s.max);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    TCLAP::CmdLine cmd(
        "Feature pool benchmark: build and query cost and matching accuracy of the "
        "candidate indexes (FLANN trees and checks, nanoflann, per-keyframe indexes, the "
        "frustum filter) on the windows of a real run.",
        ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argIn("IN", "input rawlog", true, "", "IN.rawlog", cmd);
    TCLAP::ValueArg<std::string> argConfig("c", "config", "pipeline INI (default: built-in)", false,
                                           "", "PIPELINE.ini", cmd);
    TCLAP::ValueArg<int> argQueries("n", "queries", "query frames, evenly spaced (default 40)",
                                    false, 40, "N", cmd);
    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "bench-pool")) return *exitCode;

    SlamOptions options;
    if (argConfig.isSet()) options = SlamOptions::fromFile(argConfig.getValue());
    options.tracker.poolInBackground = false;

    // The map, and the pose of every frame.
    std::vector<std::optional<Pose>> framePose;
    SlamSystem slam(options);
    {
      RawlogReader reader(argIn.getValue());
      while (auto obs = reader.next()) {
        obs->load();
        const TrackingResult r = slam.process(*obs);
        obs->unload();
        framePose.push_back(r.status == TrackingStatus::Lost ? std::nullopt
                                                             : std::optional<Pose>(r.pose));
      }
    }
    slam.finish();
    const KeyframeGraph& graph = *slam.graph();
    std::fprintf(stderr, "bench-pool: %zu frames, %zu keyframes\n", framePose.size(),
                 graph.keyframeCount());

    const FeaturePoolOptions base = options.tracker.pool;
    std::vector<Candidate> candidates;
    auto add = [&](const std::string& name, auto change, bool perKeyframe = false) {
      FeaturePoolOptions o = base;
      change(o);
      candidates.push_back({name, o, perKeyframe});
    };
    for (int trees : {1, 2, 4, 8})
      for (int checks : {16, 32, 64})
        add("flann " + std::to_string(trees) + " trees, " + std::to_string(checks) + " checks",
            [&](FeaturePoolOptions& o) {
              o.kdTrees = trees;
              o.checks = checks;
            });
    add("flann 4 trees, 16 checks, no frustum filter",
        [](FeaturePoolOptions& o) { o.frustumFilter = false; });
    add(
        "flann 4 trees, 16 checks, one index per keyframe", [](FeaturePoolOptions&) {}, true);
    add("nanoflann (exact KD-tree)",
        [](FeaturePoolOptions& o) { o.index = PoolIndexType::Nanoflann; });

    // Query frames and their features.
    const size_t q = std::max(1, argQueries.getValue());
    std::set<size_t> queryFrames;
    for (size_t i = 0; i < q; ++i) {
      const size_t f = (framePose.size() - 1) * (2 * i + 1) / (2 * q);
      if (framePose[f]) queryFrames.insert(f);
    }
    FeatureExtractor extractor(options.features);
    std::vector<Figures> figures(candidates.size());
    RawlogReader reader(argIn.getValue());
    const double W = options.tracker.windowSize;
    for (size_t index = 0; auto obs = reader.next(); ++index) {
      if (!queryFrames.count(index)) continue;
      obs->load();
      const RgbdFrame frame = RgbdFrame::fromObservation(*obs);
      const FeatureSet features = extractor.extract(frame);
      const Pose& center = *framePose[index];
      // The active window: keyframes in the W x W square (ground-parallel x, z) around the frame.
      std::vector<KeyframeId> window;
      for (const auto& [id, pose] : graph.poses())
        if (std::abs(pose.translation().x() - center.translation().x()) <= W / 2 &&
            std::abs(pose.translation().z() - center.translation().z()) <= W / 2)
          window.push_back(id);

      FeaturePoolOptions exactOptions = base;
      exactOptions.index = PoolIndexType::Exact;
      FeaturePool exact(exactOptions);
      exact.build(graph, window, center, frame.intrinsics());
      const MatchSet reference =
          matchSet(exact, exact.match(features.descriptors, options.tracker.ratioThreshold));
      for (size_t c = 0; c < candidates.size(); ++c) {
        const Candidate& cand = candidates[c];
        FeaturePool pool(cand.options);
        const auto t = Clock::now();
        if (cand.perKeyframe) {
          for (KeyframeId id : window)
            pool.append(
                std::make_shared<const PoolPart>(PoolSnapshot::of(graph, {id}), cand.options));
        } else {
          pool.build(graph, window, center, frame.intrinsics());
        }
        const double buildMs = msSince(t);
        const auto t2 = Clock::now();
        const auto matches = pool.match(features.descriptors, options.tracker.ratioThreshold);
        const double matchMs = msSince(t2);
        const MatchSet found = matchSet(pool, matches);
        size_t agree = 0;
        for (const auto& m : found) agree += reference.count(m);
        Figures& fig = figures[c];
        // Per-keyframe indexes are built once per keyframe, not per window: per keyframe cost.
        fig.buildMs.push_back(cand.perKeyframe ? buildMs / std::max<size_t>(1, window.size())
                                               : buildMs);
        fig.matchMs.push_back(matchMs);
        fig.recall.push_back(reference.empty() ? 1.0 : double(agree) / reference.size());
        fig.precision.push_back(found.empty() ? 1.0 : double(agree) / found.size());
        fig.features.push_back(static_cast<double>(pool.size()));
      }
      obs->unload();
    }

    std::printf("%zu query frames of %s, %zu keyframes; exact = brute-force search\n\n",
                queryFrames.size(), argIn.getValue().c_str(), graph.keyframeCount());
    std::printf(
        "| index | pool features median/max | build ms median/max | match ms median/max | "
        "recall | precision |\n|---|---|---|---|---|---|\n");
    for (size_t c = 0; c < candidates.size(); ++c) {
      const Figures& f = figures[c];
      std::printf("| %s | %s | %s%s | %s | %.3f | %.3f |\n", candidates[c].name.c_str(),
                  stats(f.features, "%.0f/%.0f").c_str(), stats(f.buildMs, "%.1f/%.1f").c_str(),
                  candidates[c].perKeyframe ? " per keyframe" : "",
                  stats(f.matchMs, "%.2f/%.2f").c_str(),
                  eval::ErrorStatistics::compute(f.recall).median,
                  eval::ErrorStatistics::compute(f.precision).median);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench-pool: error: " << e.what() << "\n";
  }
  return 1;
}
