#pragma once
// Loop Closing as a stage of the pipeline (issue 46), beside Camera Tracking and Local
// Optimization: each new keyframe goes through place recognition; an accepted loop is linked
// into the graph (its matches, weighed as the tracker weighs its own) and corrected: a
// pose-graph optimization of the whole map, then the relative bundle adjustment around both
// ends of the loop.

#include <slamdunk/loop_closing/PlaceRecognition.h>
#include <slamdunk/optimization/LocalOptimizer.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <functional>
#include <memory>
#include <mutex>
#include <vector>

namespace slamdunk {

struct LoopClosingStatistics {
  size_t loops = 0;                  ///< loops accepted and corrected
  size_t joins = 0;                  ///< of those, loops that joined two components of the map
  size_t candidatesVerified = 0;     ///< keyframes checked by matching and RANSAC
  size_t candidatesRefused = 0;      ///< of those, verified but farther than any drift
  size_t joinsRefused = 0;           ///< joins the map's other keyframes contradicted
  std::vector<double> detectionMs;   ///< one per keyframe looked up
  std::vector<double> correctionMs;  ///< one per corrected loop
  /// Metres: largest keyframe move of a correction (the pose graph's, after a join has moved
  /// the newer component rigidly onto the older).
  double maxCorrection = 0;
};

class LoopClosing {
 public:
  /// The tracker's options weigh the loop's matches as its own edges are weighed.
  LoopClosing(const LoopClosingOptions& options, const LocalOptimizerOptions& optimizer,
              const TrackerOptions& tracker, std::shared_ptr<KeyframeGraph> graph);

  /// Looks keyframe `id` up (reads the graph only); the loops it accepts, if any. detect() and
  /// correct() run on one thread at a time (the back end's); statistics() from any.
  std::vector<LoopHypothesis> detect(KeyframeId id);
  /// Writes a solved correction into the graph: runs `write` (the corrected poses and the
  /// loops' links, at once) where the caller wants it, for a live pipeline between two frames,
  /// and tells the tracker there: its next frame then starts in the corrected map.
  using CorrectionWriter = std::function<void(const std::function<void()>& write)>;
  /// Links and corrects the loops `detect()` accepted. The join and the pose graph are solved
  /// on a copy of the graph, then written by `writer` (directly when empty); the bundle
  /// adjustments around the loop's ends follow in the graph. Nothing else may write poses
  /// meanwhile; keyframes may be added: they move with the newest keyframe corrected.
  void correct(const std::vector<LoopHypothesis>& loops, const DepthNoiseModel& noise,
               const CorrectionWriter& writer = {});
  LoopClosingStatistics statistics() const;
  const LoopClosingOptions& options() const { return options_; }

 private:
  /// A loop between two unconnected components: the one whose keyframes are newer moves
  /// rigidly into the older one's frame (a loaded map keeps its own), by the motion that best
  /// fits the matches of every loop in `loops` between the two at once (`matches`, one list
  /// per loop); the pose graph then leaves those loops out.
  void joinComponents(KeyframeGraph& graph, const LoopHypothesis& loop,
                      const std::vector<LoopHypothesis>& loops,
                      const std::vector<std::vector<PointMatch>>& matches) const;
  /// The loop's inliers as graph matches, weighed as the tracker weighs its own.
  std::vector<PointMatch> loopMatches(const LoopHypothesis& h, const DepthNoiseModel& noise) const;

  LoopClosingOptions options_;
  LocalOptimizerOptions optimizer_;
  EdgeInformation edgeInformation_;
  double keypointScaleSigma_;
  std::shared_ptr<KeyframeGraph> graph_;
  PlaceRecognition recognition_;
  mutable std::mutex statsMutex_;
  LoopClosingStatistics stats_;
};

}  // namespace slamdunk
