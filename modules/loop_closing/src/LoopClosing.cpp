#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/loop_closing/LoopClosing.h>
#include <slamdunk/tracking/KeyframeEdges.h>

#include <algorithm>

namespace slamdunk {

namespace {
LoopClosingOptions withTrackerRansac(LoopClosingOptions o, const TrackerOptions& tracker) {
  o.ransac = tracker.ransac;
  return o;
}
}  // namespace

LoopClosing::LoopClosing(const LoopClosingOptions& options, const LocalOptimizerOptions& optimizer,
                         const TrackerOptions& tracker, std::shared_ptr<KeyframeGraph> graph)
    : options_(withTrackerRansac(options, tracker)),
      optimizer_(optimizer),
      edgeInformation_(tracker.edgeInformation),
      keypointScaleSigma_(tracker.keypointScaleSigma),
      graph_(std::move(graph)),
      recognition_(options_) {}

std::vector<LoopHypothesis> LoopClosing::detect(KeyframeId id) {
  const auto t0 = SteadyClock::now();
  PlaceRecognition::Detection d = recognition_.keyframeAdded(*graph_, id);
  std::lock_guard lock(statsMutex_);
  stats_.candidatesVerified += d.candidatesVerified;
  stats_.candidatesRefused += d.candidatesRefused;
  stats_.joinsRefused += d.joinsRefused;
  stats_.detectionMs.push_back(msSince(t0));
  return std::move(d.accepted);
}

void LoopClosing::correct(const std::vector<LoopHypothesis>& loops, const DepthNoiseModel& noise,
                          const std::function<void()>& linked) {
  if (loops.empty()) return;
  const auto t0 = SteadyClock::now();
  // The poses first, from the loops' relative poses alone: the matches' edges, added after,
  // then start the bundle adjustment close to where they agree.
  std::vector<RelativePoseConstraint> constraints;
  bool joined = false;
  for (const LoopHypothesis& h : loops) {
    if (h.joins && !joined) joinComponents(h);  // its agreeing successors join the same two
    joined = joined || h.joins;
    constraints.push_back({h.candidate, h.query, h.T_candidate_query});
  }
  const PoseGraphReport poseGraph = optimizePoseGraph(*graph_, constraints, options_.poseGraph);
  if (!poseGraph.usable) {
    if (linked) linked();  // a join may have moved a component already
    return;
  }
  for (const LoopHypothesis& h : loops) {
    const KeyframePtr candidate = graph_->keyframe(h.candidate);
    const KeyframePtr query = graph_->keyframe(h.query);
    if (!candidate || !query) continue;
    std::vector<PointMatch> matches;
    for (const LoopHypothesis::Match& m : h.inliers)
      matches.push_back(weighedPointMatch(candidate->features, m.candidateFeature, query->features,
                                          m.queryFeature, m.ratio, h.T_candidate_query.linear(),
                                          noise, edgeInformation_, keypointScaleSigma_));
    graph_->addMatches(h.candidate, h.query, matches);
  }
  if (linked) linked();
  LocalOptimizerOptions o = optimizer_;
  o.noise = noise;
  const LocalOptimizer optimizer(o);
  optimizer.optimize(*graph_, loops.back().query);
  optimizer.optimize(*graph_, loops.back().candidate);
  recognition_.resetConsistency();
  std::lock_guard lock(statsMutex_);
  ++stats_.loops;
  if (joined) ++stats_.joins;
  stats_.maxCorrection = std::max(stats_.maxCorrection, poseGraph.maxTranslationChange);
  stats_.correctionMs.push_back(msSince(t0));
}

void LoopClosing::joinComponents(const LoopHypothesis& loop) {
  const std::map<KeyframeId, int> queryPart = graph_->component(loop.query);
  const std::map<KeyframeId, int> candidatePart = graph_->component(loop.candidate);
  if (queryPart.empty() || candidatePart.empty() || queryPart.count(loop.candidate)) return;
  // Maps the query's component's frame into the candidate's, as the loop measured it.
  const Pose queryToCandidate =
      graph_->pose(loop.candidate) * loop.T_candidate_query * graph_->pose(loop.query).inverse();
  const bool queryNewer = queryPart.begin()->first > candidatePart.begin()->first;
  const std::map<KeyframeId, int>& moving = queryNewer ? queryPart : candidatePart;
  const Pose move = queryNewer ? queryToCandidate : Pose(queryToCandidate.inverse());
  std::map<KeyframeId, Pose> moved;
  for (const auto& [id, pose] : graph_->poses())
    if (moving.count(id)) moved[id] = orthonormalized(move * pose);
  // The tracker adds keyframes to the query's component: those added meanwhile move with it.
  if (queryNewer)
    graph_->applyCorrection(moved, moving.rbegin()->first);
  else
    graph_->setPoses(moved);
}

LoopClosingStatistics LoopClosing::statistics() const {
  std::lock_guard lock(statsMutex_);
  return stats_;
}

}  // namespace slamdunk
