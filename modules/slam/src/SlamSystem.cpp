#include <slamdunk/slam/SlamSystem.h>

#include <mrpt/system/datetime.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace slamdunk {

SlamSystem::SlamSystem(const SlamOptions& options, std::shared_ptr<KeyframeGraph> graph)
    : options_(options),
      graph_(graph ? std::move(graph) : std::make_shared<KeyframeGraph>()),
      tracker_(options.tracker, options.features, graph_),
      loopClosing_(options.loopClosing.enabled
                       ? std::make_unique<LoopClosing>(options.loopClosing, options.optimizer,
                                                       options.tracker, graph_)
                       : nullptr),
      optimization_(
          options.optimizer, graph_, options.localOptimization && options.optimizerThread,
          [this] { tracker_.notifyMapChanged(); },
          [this](KeyframeId id, const DepthNoiseModel& noise) { closeLoops(id, noise); }) {
  if (options.tracker.localizationOnly && graph_->keyframeCount() == 0)
    throw std::invalid_argument(
        "[tracker] localization_only: there is no map to localize in (give one: --load-map)");
  if (options.tracker.localizationOnly) graph_->anchor(graph_->ids());
}

SlamSystem::~SlamSystem() = default;

std::optional<TrackingResult> SlamSystem::outOfOrder(double timestamp) {
  const size_t index = framesGiven_++;
  // Stamps that repeat or go backwards (a driver glitch, a clock reset, recordings joined):
  // such a frame would make the trajectory's stamps non-increasing (not a valid TUM file, and
  // ambiguous for evaluation) and its motion model's time step zero or negative.
  if (!lastProcessedTimestamp_ || timestamp > *lastProcessedTimestamp_) {
    lastProcessedIndex_ = index;
    lastProcessedTimestamp_ = timestamp;
    return std::nullopt;
  }
  char why[200];
  std::snprintf(why, sizeof why,
                "frame %zu: timestamp %.6f is not after frame %zu's %.6f (repeated or going "
                "backwards): skipped",
                index, timestamp, lastProcessedIndex_, *lastProcessedTimestamp_);
  TrackingResult r;
  r.timestamp = timestamp;
  r.status = TrackingStatus::Lost;
  r.skipped = true;
  r.lostReason = why;
  std::lock_guard lock(statsMutex_);
  ++stats_.framesOutOfOrder;
  if (stats_.outOfOrderExamples.size() < 5) stats_.outOfOrderExamples.push_back(why);
  return r;
}

TrackingResult SlamSystem::process(const mrpt::obs::CObservation3DRangeScan& obs) {
  const double timestamp = mrpt::Clock::toDouble(obs.timestamp);
  if (auto skipped = outOfOrder(timestamp)) return *skipped;
  try {
    return track(RgbdFrame::fromObservation(obs));
  } catch (const std::exception& e) {
    return unusable(timestamp, e.what());
  }
}

TrackingResult SlamSystem::process(PreparedFrame prepared) {
  const double timestamp = prepared.timestamp();
  if (auto skipped = outOfOrder(timestamp)) return *skipped;
  if (!prepared.frame) return unusable(timestamp, prepared.error);
  try {
    return track(*prepared.frame, &prepared);
  } catch (const std::exception& e) {
    return unusable(timestamp, e.what());
  }
}

TrackingResult SlamSystem::unusable(double timestamp, const std::string& why) {
  TrackingResult r;
  r.timestamp = timestamp;
  r.status = TrackingStatus::Lost;
  r.lostReason = "unusable observation: " + why;
  frames_.push_back({r.timestamp, r.status, 0, Pose::Identity()});
  std::lock_guard lock(statsMutex_);
  ++stats_.frames;
  ++stats_.lost;
  if (std::find(stats_.lostReasons.begin(), stats_.lostReasons.end(), r.lostReason) ==
      stats_.lostReasons.end())
    stats_.lostReasons.push_back(r.lostReason);
  return r;
}

size_t reviseFrameRecords(SessionLog<FrameRecord>& records,
                          const std::vector<TrackingResult::RevisedFrame>& revised) {
  size_t replaced = 0;
  size_t fromNewest = 0;
  for (auto it = revised.rbegin(); it != revised.rend(); ++it) {  // newest first, like the walk
    FrameRecord* record = records.recent(fromNewest);
    while (record && record->timestamp > it->timestamp) record = records.recent(++fromNewest);
    if (!record || record->timestamp != it->timestamp) break;
    record->reference = it->reference;
    record->poseInReference = it->poseInReference;
    ++replaced;
  }
  return replaced;
}

TrackingResult SlamSystem::process(const RgbdFrame& frame) {
  if (auto skipped = outOfOrder(frame.timestamp())) return *skipped;
  return track(frame);
}

TrackingResult SlamSystem::track(const RgbdFrame& frame, PreparedFrame* prepared) {
  TrackingResult r;
  {
    // A loop correction is written between two frames, never under one (closeLoops).
    std::lock_guard betweenFrames(frameMutex_);
    r = prepared ? tracker_.process(frame, std::move(prepared->features), prepared->extractionMs)
                 : tracker_.process(frame);
  }
  reviseFrameRecords(frames_, r.revisedFrames);
  frames_.push_back({r.timestamp, r.status, r.reference, r.poseInReference});
  {
    std::lock_guard lock(statsMutex_);
    ++stats_.frames;
    stats_.stageTimings.push_back(r.timings);
    if (r.status == TrackingStatus::Lost) {
      ++stats_.lost;
      // Reasons carry numbers; keep the distinct leading phrase only to bound the list.
      const std::string key = r.lostReason.substr(0, r.lostReason.find_first_of("0123456789"));
      if (std::none_of(stats_.lostReasons.begin(), stats_.lostReasons.end(),
                       [&](const std::string& s) { return s.rfind(key, 0) == 0; }))
        stats_.lostReasons.push_back(r.lostReason);
    } else {
      ++stats_.tracked;
      if (r.depthOnly) ++stats_.trackedDepthOnly;
      if (r.relocalized) ++stats_.relocalizations;
    }
    if (r.newKeyframe) ++stats_.keyframes;
    if (r.newComponent) ++stats_.componentsStarted;
    if (r.outsideMap) ++stats_.framesOutsideMap;
    if (r.newComponent) separateComponent_ = true;
    if (r.loopCorrected) separateComponent_ = apartAfterCorrection_.load();
    if (r.relocalized && separateComponent_)  // perhaps into the map's first component
      separateComponent_ = !graph_->connected(graph_->ids().front(), r.reference);
    stats_.keyframes -= r.culledKeyframes.size();
    stats_.keyframesCulled += r.culledKeyframes.size();
    if (r.loopClosure) ++stats_.loopClosures;
  }
  // The same precisions as the tracker's, which learns them (KeypointNoiseEstimator).
  if (r.newKeyframe && options_.localOptimization && graph_->keyframeCount() > 1)
    optimization_.keyframeAdded(r.keyframeId, tracker_.noiseModel());
  return r;
}

void SlamSystem::closeLoops(KeyframeId keyframe, const DepthNoiseModel& noise) {
  if (!loopClosing_) return;
  const std::vector<LoopHypothesis> loops = loopClosing_->detect(keyframe);
  if (loops.empty()) return;
  loopClosing_->correct(loops, noise, [&](const std::function<void()>& write) {
    // Between two frames: the tracker's next frame starts in the corrected map, and knows it.
    std::lock_guard betweenFrames(frameMutex_);
    write();
    // Joined to the map's first component, or to another one (checked on this rare event
    // only: a walk over the whole graph). The tracker's next frame reports both at once. Asked
    // of the loop's keyframe, whose edges are in the graph: the newest keyframe may have been
    // added by the tracker a moment ago, before its edges, and would look apart from
    // everything.
    apartAfterCorrection_ = !graph_->connected(graph_->ids().front(), keyframe);
    tracker_.notifyMapCorrected();
  });
  tracker_.notifyMapChanged();  // the bundle adjustments after the correction moved keyframes
}

void SlamSystem::finish() {
  optimization_.waitUntilIdle();
  if (options_.globalPassAtEnd && graph_->keyframeCount() > 1)
    optimization_.optimizeWholeGraph(tracker_.noiseModel());
  if (!options_.tracker.localizationOnly) holdTheMapInTheFirstCameraFrame();
}

void SlamSystem::holdTheMapInTheFirstCameraFrame() {
  const std::map<KeyframeId, Pose> poses = graph_->poses();
  if (poses.empty()) return;
  graph_->setPoses(movedRigidly(poses, poses.begin()->second.inverse()));
}

size_t forEachTrackedPose(const SessionLog<FrameRecord>& records, const KeyframeGraph& graph,
                          const std::function<void(double, const Pose&)>& visit) {
  const auto poses = graph.poses();  // one reading: the trajectory is of one map
  size_t tracked = 0;
  records.forEach([&](const FrameRecord& f) {
    if (f.status == TrackingStatus::Lost) return;
    const auto it = poses.find(f.reference);
    // A reference culled since the frame was tracked: its successor stands in for it.
    const std::optional<Pose> reference =
        it != poses.end() ? std::optional<Pose>(it->second) : graph.findPose(f.reference);
    if (!reference) return;
    visit(f.timestamp, *reference * f.poseInReference);
    ++tracked;
  });
  return tracked;
}

Trajectory SlamSystem::trajectory() const {
  Trajectory out;
  forEachTrackedPose(frames_, *graph_, [&](double t, const Pose& pose) {
    out.push_back({t, pose});
  });
  return out;
}

Trajectory SlamSystem::keyframeTrajectory() const {
  Trajectory out;
  for (const auto& [id, pose] : graph_->poses())
    if (const KeyframePtr kf = graph_->keyframe(id))  // not culled meanwhile (live)
      out.push_back({kf->timestamp, pose});
  return out;
}

SlamStatistics SlamSystem::statistics() const {
  std::lock_guard lock(statsMutex_);
  SlamStatistics s = stats_;
  const LocalOptimization::Statistics optimization = optimization_.statistics();
  s.optimizations = optimization.optimizations;
  s.optimizationMs = optimization.optimizationMs;
  s.maxOptimizationTranslation = optimization.maxTranslationChange;
  s.maxOptimizationRotationDeg = optimization.maxRotationChangeDeg;
  s.poolPreparation = tracker_.localMap().statistics();
  if (loopClosing_) s.placeLoops = loopClosing_->statistics();
  s.rollingShutterMs = tracker_.rollingShutterMs();
  s.keypointNoise = tracker_.noiseModel();
  return s;
}

}  // namespace slamdunk
