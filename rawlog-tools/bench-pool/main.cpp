// bench-pool: what the feature pool's index costs and how well it matches. Runs SlamDunk over a
// rawlog to get a map and each frame's pose, then, at evenly spaced query frames, builds the pool
// of the active window around the frame's pose with each candidate index and matches the frame's
// features against it. Matches are compared with those of an exact (brute-force) index: recall
// is the share of the exact ratio-test matches a candidate finds, precision the share of its
// matches the exact search agrees with.

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/slam/SlamSystem.h>

#include <cstdio>
#include <iostream>
#include <map>
#include <set>

using namespace slamdunk;

namespace {

/// How a candidate lays out the pool.
enum class Layout {
  Window,       ///< one part over the whole active window
  PerKeyframe,  ///< one part per keyframe of the window (built once when the keyframe is made)
  OneKeyframe   ///< only the window's newest keyframe: the part a new keyframe adds to the pool
};

struct Candidate {
  std::string name;
  FeaturePoolOptions options;
  Layout layout = Layout::Window;
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
  return slamdunk::runTool("bench-pool", [&] {
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
    options.tracker.localMap.backgroundPreparation = false;

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

    // Every part indexed as the candidate says, however small, unless it says otherwise.
    FeaturePoolOptions base = options.tracker.localMap.pool;
    base.bruteForceBelow = 0;
    std::vector<Candidate> candidates;
    auto add = [&](const std::string& name, auto change, Layout layout = Layout::Window) {
      FeaturePoolOptions o = base;
      change(o);
      candidates.push_back({name, o, layout});
    };
    auto bruteForce = [](FeaturePoolOptions& o) { o.index = PoolIndexType::Exact; };
    auto flann = [](int trees, int checks) {
      return [trees, checks](FeaturePoolOptions& o) {
        o.index = PoolIndexType::Flann;
        o.kdTrees = trees;
        o.checks = checks;
      };
    };
    for (int trees : {1, 2, 4, 8})
      for (int checks : {16, 32, 64})
        add("flann " + std::to_string(trees) + " trees, " + std::to_string(checks) + " checks",
            flann(trees, checks));
    for (int checks : {32, 48, 64, 96})
      add("kdtree, " + std::to_string(checks) + " checks", [checks](FeaturePoolOptions& o) {
        o.index = PoolIndexType::KdTree;
        o.checks = checks;
      });
    add("flann 4 trees, 16 checks, no frustum filter", [&](FeaturePoolOptions& o) {
      flann(4, 16)(o);
      o.frustumFilter = false;
    });
    add("flann 4 trees, 16 checks, one index per keyframe", flann(4, 16), Layout::PerKeyframe);
    add("nanoflann (exact KD-tree)",
        [](FeaturePoolOptions& o) { o.index = PoolIndexType::Nanoflann; });
    add("brute force", bruteForce);
    add("brute force, one part per keyframe", bruteForce, Layout::PerKeyframe);
    add("new keyframe's part: flann 1 tree, 64 checks", flann(1, 64), Layout::OneKeyframe);
    add("new keyframe's part: brute force", bruteForce, Layout::OneKeyframe);

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
    const double W = options.tracker.localMap.windowSize;
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

      if (window.empty()) continue;
      // A new keyframe's part has all its features (no frustum); the nearest keyframe stands in.
      const KeyframeId nearest =
          *std::min_element(window.begin(), window.end(), [&](auto a, auto b) {
            return translationDistance(graph.pose(a), center) <
                   translationDistance(graph.pose(b), center);
          });
      auto buildPool = [&](FeaturePool& pool, Layout layout, const FeaturePoolOptions& o) {
        if (layout == Layout::Window) {
          pool.build(graph, window, center, frame.intrinsics());
          return;
        }
        for (KeyframeId id : layout == Layout::PerKeyframe ? window : std::vector{nearest})
          pool.append(std::make_shared<const PoolPart>(PoolSnapshot::of(graph, {id}), o));
      };
      FeaturePoolOptions exactOptions = base;
      bruteForce(exactOptions);
      auto exactMatches = [&](Layout layout) {
        FeaturePool exact(exactOptions);
        buildPool(exact, layout, exactOptions);
        return matchSet(exact, exact.match(features.descriptors, options.tracker.ratioThreshold));
      };
      const MatchSet windowReference = exactMatches(Layout::Window);
      const MatchSet nearestReference = exactMatches(Layout::OneKeyframe);
      for (size_t c = 0; c < candidates.size(); ++c) {
        const Candidate& cand = candidates[c];
        FeaturePool pool(cand.options);
        const auto t = SteadyClock::now();
        buildPool(pool, cand.layout, cand.options);
        const MatchSet& reference =
            cand.layout == Layout::OneKeyframe ? nearestReference : windowReference;
        const double buildMs = msSince(t);
        const auto t2 = SteadyClock::now();
        const auto matches = pool.match(features.descriptors, options.tracker.ratioThreshold);
        const double matchMs = msSince(t2);
        const MatchSet found = matchSet(pool, matches);
        size_t agree = 0;
        for (const auto& m : found) agree += reference.count(m);
        Figures& fig = figures[c];
        // Per-keyframe indexes are built once per keyframe, not per window: per keyframe cost.
        fig.buildMs.push_back(cand.layout == Layout::PerKeyframe
                                  ? buildMs / std::max<size_t>(1, window.size())
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
                  candidates[c].layout == Layout::PerKeyframe ? " per keyframe" : "",
                  stats(f.matchMs, "%.2f/%.2f").c_str(),
                  eval::ErrorStatistics::compute(f.recall).median,
                  eval::ErrorStatistics::compute(f.precision).median);
    }
    return 0;
  });
}
