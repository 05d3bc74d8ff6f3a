#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/loop_closing/LoopClosing.h>
#include <slamdunk/optimization/ComponentMotion.h>
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

std::vector<PointMatch> LoopClosing::loopMatches(const LoopHypothesis& h,
                                                 const DepthNoiseModel& noise) const {
  std::vector<PointMatch> matches;
  const KeyframePtr candidate = graph_->keyframe(h.candidate);
  const KeyframePtr query = graph_->keyframe(h.query);
  if (!candidate || !query) return matches;
  for (const LoopHypothesis::Match& m : h.inliers)
    matches.push_back(weighedPointMatch(candidate->features, m.candidateFeature, query->features,
                                        m.queryFeature, m.ratio, h.T_candidate_query.linear(),
                                        noise, edgeInformation_, keypointScaleSigma_));
  return matches;
}

void LoopClosing::correct(const std::vector<LoopHypothesis>& loops, const DepthNoiseModel& noise,
                          const CorrectionWriter& writer) {
  if (loops.empty()) return;
  const auto t0 = SteadyClock::now();
  std::vector<std::vector<PointMatch>> matches;
  for (const LoopHypothesis& h : loops) matches.push_back(loopMatches(h, noise));
  // Solved on a copy: a frame tracked meanwhile reads the map as it was, all of it.
  const std::shared_ptr<KeyframeGraph> solved = graph_->snapshot();
  const auto firstJoin =
      std::find_if(loops.begin(), loops.end(), [](const LoopHypothesis& h) { return h.joins; });
  const bool joined = firstJoin != loops.end();
  // The first join's successors join the same two components.
  if (joined) joinComponents(*solved, *firstJoin, loops, matches);
  // The poses first, from the loops' relative poses alone: the matches' edges, added after,
  // then start the bundle adjustment close to where they agree.
  std::vector<RelativePoseConstraint> constraints;
  // A join's loops are not among them: the fit placed the newer component by all their
  // matches, and a weak loop's relative pose would bend it again (docs/experiments.md).
  for (const LoopHypothesis& h : loops)
    if (!h.joins) constraints.push_back({h.candidate, h.query, h.T_candidate_query});
  const PoseGraphReport poseGraph = optimizePoseGraph(*solved, constraints, options_.poseGraph);
  const std::map<KeyframeId, Pose> corrected = solved->poses();
  const auto write = [&] {
    // Keyframes the tracker added since the copy move with the newest one corrected.
    if ((joined || poseGraph.usable) && !corrected.empty())
      graph_->applyCorrection(corrected, corrected.rbegin()->first);
    if (!poseGraph.usable) return;
    for (size_t k = 0; k < loops.size(); ++k)
      if (!matches[k].empty()) graph_->addMatches(loops[k].candidate, loops[k].query, matches[k]);
  };
  if (writer)
    writer(write);
  else
    write();
  if (!poseGraph.usable) return;
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

void LoopClosing::joinComponents(KeyframeGraph& graph, const LoopHypothesis& loop,
                                 const std::vector<LoopHypothesis>& loops,
                                 const std::vector<std::vector<PointMatch>>& matches) const {
  const std::map<KeyframeId, int> queryPart = graph.component(loop.query);
  const std::map<KeyframeId, int> candidatePart = graph.component(loop.candidate);
  if (queryPart.empty() || candidatePart.empty() || queryPart.count(loop.candidate)) return;
  const std::map<KeyframeId, Pose> poses = graph.poses();
  // Maps the query's component's frame into the candidate's, as the loop measured it.
  const Pose queryToCandidate =
      poses.at(loop.candidate) * loop.T_candidate_query * poses.at(loop.query).inverse();
  const bool queryNewer = queryPart.begin()->first > candidatePart.begin()->first;
  const std::map<KeyframeId, int>& moving = queryNewer ? queryPart : candidatePart;
  Pose move = queryNewer ? queryToCandidate : Pose(queryToCandidate.inverse());
  // Then fitted to the matches of every loop between the two parts at once.
  std::vector<AnchoredMatches> anchored;
  for (size_t k = 0; k < loops.size(); ++k) {
    const LoopHypothesis& h = loops[k];
    if (!queryPart.count(h.query) || !candidatePart.count(h.candidate)) continue;
    if (queryNewer) {
      anchored.push_back({poses.at(h.candidate), poses.at(h.query), matches[k]});
    } else {
      AnchoredMatches a{poses.at(h.query), poses.at(h.candidate), {}};
      const Eigen::Matrix3d R = h.T_candidate_query.linear();
      for (PointMatch m : matches[k]) {
        std::swap(m.pointI, m.pointJ);
        std::swap(m.featureI, m.featureJ);
        m.information = R.transpose() * m.information.matrix() * R;
        a.matches.push_back(m);
      }
      anchored.push_back(std::move(a));
    }
  }
  if (const std::optional<Pose> fitted = fitRigidMotion(anchored, move)) move = *fitted;
  graph.setPoses(movedRigidly(poses, move, &moving));
}

LoopClosingStatistics LoopClosing::statistics() const {
  std::lock_guard lock(statsMutex_);
  return stats_;
}

}  // namespace slamdunk
