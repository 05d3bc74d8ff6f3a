#pragma once
// Local Optimization as a stage of the pipeline (paper Sec. 4.3): each new keyframe asks for a
// relative bundle adjustment around it, run inline (offline: deterministic) or on a thread of
// its own beside tracking (live). On its thread the newest request wins: a backlog of keyframes
// collapses into one optimization around the newest.

#include <slamdunk/optimization/LocalOptimizer.h>

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace slamdunk {

class LocalOptimization {
 public:
  struct Statistics {
    size_t optimizations = 0;
    std::vector<double> optimizationMs;  ///< one per optimization, in order
    double maxTranslationChange = 0;     ///< metres: largest pose change by any optimization
    double maxRotationChangeDeg = 0;
  };

  /// What runs after each optimization around a new keyframe, on the same thread (loop
  /// closing: the back end's steps never write poses at the same time).
  using FollowUp = std::function<void(KeyframeId root, const DepthNoiseModel& noise)>;

  /// `mapChanged` is called after each optimization (from the optimizing thread): the tracker
  /// re-reads the keyframe poses it moved. Then `followUp`, if any.
  LocalOptimization(const LocalOptimizerOptions& options, std::shared_ptr<KeyframeGraph> graph,
                    bool ownThread, std::function<void()> mapChanged, FollowUp followUp = {});
  ~LocalOptimization();  ///< stops the thread (a running optimization finishes first)
  LocalOptimization(const LocalOptimization&) = delete;
  LocalOptimization& operator=(const LocalOptimization&) = delete;

  /// Optimizes around `root`, weighing the features with `noise` (the tracker's learned model):
  /// now, or queued for the thread.
  void keyframeAdded(KeyframeId root, const DepthNoiseModel& noise);
  /// Returns once no optimization is queued or running.
  void waitUntilIdle();
  /// One optimization over the whole graph (the optional global pass at the end of a run).
  void optimizeWholeGraph(const DepthNoiseModel& noise);
  Statistics statistics() const;

 private:
  LocalOptimizer optimizerFor(const DepthNoiseModel& noise) const;
  void optimizeAround(KeyframeId root, const DepthNoiseModel& noise);
  void loop();

  LocalOptimizerOptions options_;
  std::shared_ptr<KeyframeGraph> graph_;
  std::function<void()> mapChanged_;
  FollowUp followUp_;
  mutable std::mutex statsMutex_;
  Statistics stats_;
  std::mutex jobMutex_;
  std::condition_variable jobCv_;
  bool jobPending_ = false, busy_ = false, stopping_ = false;
  KeyframeId jobRoot_ = 0;
  DepthNoiseModel jobNoise_;
  std::thread thread_;
};

}  // namespace slamdunk
