#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/optimization/LocalOptimizer.h>

#include "BundleAdjuster.h"
#include "LocalProblem.h"

#include <chrono>
#include <cmath>

namespace slamdunk {

namespace {

/// Solves a prepared problem on its own copy of the poses and, only when every result is a
/// valid pose, writes the free ones back in one setPoses() call.
LocalOptimizationReport solveAndWriteBack(KeyframeGraph& graph, const LocalProblem& p,
                                          const LocalOptimizerOptions& o,
                                          LocalOptimizationReport r) {
  r.verticesFixed = static_cast<int>(p.fixed.size());
  r.verticesOptimised = static_cast<int>(p.poses.size() - p.fixed.size());
  r.edges = static_cast<int>(p.edges.size());
  r.residuals = static_cast<int>(p.matchCount());
  r.invalidMatches = p.invalidMatches;
  r.droppedMatches = p.droppedMatches;
  if (p.edges.empty() || r.verticesOptimised == 0) {
    r.status = LocalOptimizationReport::Status::NothingToOptimise;
    r.message = "no usable edge with a free endpoint";
    return r;
  }

  const BundleAdjustmentResult result = BundleAdjuster(o).solve(p);
  r.initialCost = result.initialCost;
  r.finalCost = result.finalCost;
  r.iterations = result.iterations;
  r.rounds = result.rounds;
  r.landmarks = result.landmarks;
  r.observations = result.observations;
  r.status = LocalOptimizationReport::Status::Failed;
  if (!result.usable) {
    r.message = "solver failed: " + result.message;
    return r;
  }
  for (const auto& [id, pose] : result.freePoses) {
    if (!isValidPose(pose)) {
      r.message = "solver returned an invalid pose for keyframe " + std::to_string(id);
      return r;
    }
    const Pose& before = p.poses.at(id);
    r.maxTranslationChange = std::max(r.maxTranslationChange, translationDistance(before, pose));
    r.maxRotationChangeDeg =
        std::max(r.maxRotationChangeDeg, rotationDistance(before, pose) * 180.0 / M_PI);
  }
  graph.setPoses(result.freePoses, result.refinedPoints);
  r.status = LocalOptimizationReport::Status::Optimised;
  r.converged = result.converged;
  r.usable = true;
  r.message = result.message;
  return r;
}
}  // namespace

LocalOptimizer::LocalOptimizer(const LocalOptimizerOptions& options) : options_(options) {
  options_.validate();
}

LocalOptimizationReport LocalOptimizer::optimize(KeyframeGraph& graph, KeyframeId root) const {
  const auto t0 = SteadyClock::now();
  LocalOptimizationReport r;
  r.root = root;
  LocalProblem p;
  if (graph.contains(root)) p = snapshotRings(graph, root, options_.rings);
  if (!p.poses.count(root)) {  // unknown, or culled meanwhile (live)
    r.status = LocalOptimizationReport::Status::Failed;
    r.message = "unknown root keyframe";
  } else {
    cleanMatches(p, options_.minWeight);
    fixGauge(p, &root);
    r = solveAndWriteBack(graph, p, options_, r);
  }
  r.timeMs = msSince(t0);
  return r;
}

LocalOptimizationReport LocalOptimizer::optimizeAll(KeyframeGraph& graph) const {
  const auto t0 = SteadyClock::now();
  LocalProblem p = snapshotAll(graph);
  cleanMatches(p, options_.minWeight);
  fixGauge(p, nullptr);  // smallest id of each component
  LocalOptimizationReport r;
  r.root = p.fixed.empty() ? 0 : *p.fixed.begin();
  r = solveAndWriteBack(graph, p, options_, r);
  r.timeMs = msSince(t0);
  return r;
}

}  // namespace slamdunk
