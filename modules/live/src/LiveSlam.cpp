#include <slamdunk/live/LiveSlam.h>

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/grid_map/GridMapFiles.h>

#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SimpleMapExport.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk::live {

namespace {

/// Writes what it can: each output attempted on its own, the failures listed.
class OutputAttempts {
 public:
  explicit OutputAttempts(std::vector<std::string>& failures) : failures_(failures) {}
  template <class Write>
  void attempt(const std::string& target, Write write) {
    if (target.empty()) return;
    try {
      write();
    } catch (const std::exception& e) {
      failures_.push_back(writeErrorMessage(target, e.what()));
    }
  }

 private:
  std::vector<std::string>& failures_;
};

}  // namespace

std::unique_ptr<LiveSlam> LiveSlam::fromIniFile(const std::string& path, const LiveSession& session,
                                                const SourceOverrides& overrides) {
  LiveOptions options = LiveOptions::fromFile(path);
  auto source = makeFrameSource(*options.config, options.sourceSection, options.iniDir, overrides,
                                options.frameTimeout, options.sensorStampLatencyMs);
  return std::make_unique<LiveSlam>(std::move(options), std::move(source), session);
}

LiveSlam::LiveSlam(LiveOptions options, std::unique_ptr<FrameSource> source, LiveSession session)
    : options_(std::move(options)), source_(std::move(source)), session_(std::move(session)) {
  if (!source_) throw std::invalid_argument("LiveSlam: no frame source");
  if (!session_.trajectory.empty() && session_.keyframes.empty())
    session_.keyframes = keyframeTrajectoryPathFor(session_.trajectory);
  for (const std::string& out : {session_.trajectory, session_.keyframes, session_.map,
                                 session_.recording, session_.frameLog, session_.gridMap})
    if (!out.empty()) requireWritableFolder(out);
  if (session_.localizationOnly) options_.slam.tracker.localizationOnly = true;
  if (session_.extendMap) options_.slam.tracker.extendMap = true;
  slam_ = std::make_unique<SlamSystem>(options_.slam, session_.startMap);
  if (!session_.recording.empty()) recorder_ = std::make_unique<RawlogRecorder>(session_.recording);
  if (!session_.frameLog.empty()) {
    frameCsvOutput_ = std::make_unique<AtomicOutput>(session_.frameLog);
    try {
      frameCsv_ = std::make_unique<FrameCsvLog>(frameCsvOutput_->tempPath());
    } catch (const std::exception& e) {
      throw std::runtime_error(
          writeErrorMessage(session_.frameLog, e.what(), frameCsvOutput_->tempPath()));
    }
  }
  if (const std::string folder = checkpointFolder(); !folder.empty()) {
    checkpoints_ =
        std::make_unique<CheckpointWriter>(options_.checkpoint, folder, slam_->graph(), frameLog_,
                                           "slamdunk live session, " + source_->describe());
    if (!session_.gridMap.empty()) checkpoints_->setGridMap(options_.slam.gridMap);
  }
  pipeline_ = std::make_unique<LivePipeline>(
      *source_, *slam_, options_.queueCapacity, recorder_.get(), session_.maxFrames,
      [this](const mrpt::obs::CObservation3DRangeScan& frame, const TrackingResult& r,
             double latencyMs) { frameDone(frame, r, latencyMs); });
}

LiveSlam::~LiveSlam() {
  // Threads first: they use everything else.
  if (pipeline_) {
    pipeline_->requestStop();
    pipeline_->join();
  }
  if (checkpoints_) checkpoints_->stop();
}

std::string LiveSlam::checkpointFolder() const {
  if (!options_.checkpoint.enabled()) return {};
  if (!options_.checkpoint.folder.empty()) return options_.checkpoint.folder;
  if (session_.trajectory.empty()) return {};
  const fs::path t(session_.trajectory);
  return (t.parent_path() / (t.stem().string() + "_checkpoint")).string();
}

std::optional<CheckpointFigures> LiveSlam::checkpointFigures() const {
  if (!checkpoints_) return std::nullopt;
  return checkpoints_->figures();
}

void LiveSlam::onPose(PoseCallback callback) {
  if (started_) throw std::logic_error("LiveSlam::onPose() after start()");
  poseCallback_ = std::move(callback);
}

void LiveSlam::onFrame(FrameCallback callback) {
  if (started_) throw std::logic_error("LiveSlam::onFrame() after start()");
  frameCallback_ = std::move(callback);
}

void LiveSlam::start() {
  if (started_) return;
  started_ = true;
  if (checkpoints_) checkpoints_->start();
  pipeline_->start();
}

bool LiveSlam::waitUntilOpen(double timeoutSeconds, const std::atomic<bool>* cancel) {
  static const std::atomic<bool> never{false};
  return pipeline_->waitUntilOpen(timeoutSeconds, cancel ? *cancel : never);
}

void LiveSlam::frameDone(const mrpt::obs::CObservation3DRangeScan& frame, const TrackingResult& r,
                         double latencyMs) {
  if (frameCsv_) {
    const auto grabbed = std::chrono::steady_clock::now() -
                         std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double, std::milli>(latencyMs));
    frameCsv_->add(r, FrameCsvLog::Grab{grabbed, latencyMs});
  }
  if (r.skipped) return;  // a timestamp that did not increase: not part of the trajectory
  if (!sensorPose_) {
    sensorPose_ = frame.sensorPose;  // the camera's mounting on a robot, for the grid's floor
    if (checkpoints_) checkpoints_->setSensorPose(frame.sensorPose);
  }
  if (checkpoints_) {
    frameLog_.revise(r.revisedFrames);
    frameLog_.append({r.timestamp, r.status, r.reference, r.poseInReference});
  }
  const bool tracked = r.status != TrackingStatus::Lost;
  if (checkpoints_) checkpoints_->frameProcessed(tracked, r.newKeyframe);

  LivePose pose;
  {
    std::lock_guard lock(poseMutex_);
    pose.frameIndex = latest_.valid ? latest_.frameIndex + 1 : 0;
    // A lost frame keeps the last good pose (an unusable observation reports none at all).
    if (tracked || !latest_.valid) {
      pose.optical = r.pose;
      pose.sensor = toCPose3D(toMrptSensorWorld(r.pose));
    } else {
      pose.optical = latest_.optical;
      pose.sensor = latest_.sensor;
    }
    pose.valid = true;
    pose.timestamp = r.timestamp;
    pose.status = r.status;
    pose.newKeyframe = r.newKeyframe;
    pose.loopCorrected = r.loopCorrected;
    pose.separateComponent = slam_->inSeparateComponent();
    pose.outsideMap = r.outsideMap;
    pose.latencyMs = latencyMs;
    latest_ = pose;
  }
  try {
    if (poseCallback_) poseCallback_(pose);
  } catch (const std::exception& e) {
    callbackFailed("onPose", e);
  }
  try {
    if (frameCallback_) frameCallback_(frame, r);
  } catch (const std::exception& e) {
    callbackFailed("onFrame", e);
  }
}

void LiveSlam::callbackFailed(const char* which, const std::exception& e) {
  std::lock_guard lock(poseMutex_);
  if (callbackError_.empty()) callbackError_ = std::string(which) + " callback: " + e.what();
}

LivePose LiveSlam::latestPose() const {
  std::lock_guard lock(poseMutex_);
  return latest_;
}

LiveCounters LiveSlam::counters() const { return pipeline_->counters(); }

bool LiveSlam::finished() const { return pipeline_->finished(); }

void LiveSlam::requestStop() {
  stopRequested_ = true;
  pipeline_->requestStop();
}

LiveResult LiveSlam::finish() {
  if (finished_) throw std::logic_error("LiveSlam::finish() called twice");
  finished_ = true;
  LiveResult result;
  if (!pipeline_->finished()) requestStop();
  pipeline_->join();
  // No checkpoint after this point: the final outputs below replace it.
  if (checkpoints_) {
    checkpoints_->stop();
    result.checkpoints = checkpoints_->figures();
  }
  result.counters = pipeline_->counters();
  result.sourceError = pipeline_->error();
  result.latenciesMs = pipeline_->latenciesMs();
  result.stopRequested = stopRequested_;
  {
    std::lock_guard lock(poseMutex_);
    result.callbackError = callbackError_;
  }
  if (result.counters.processed == 0 && !result.sourceError.empty())
    throw std::runtime_error(result.sourceError);
  if (result.counters.processed == 0 && !result.stopRequested)
    throw std::runtime_error("the source delivered no RGB-D frame: " + source_->describe());

  slam_->finish();
  result.stats = slam_->statistics();
  result.trajectory = slam_->trajectory();
  result.keyframes = slam_->keyframeTrajectory();
  result.graph = slam_->graph();
  result.mapMemory = result.graph->memory();
  const std::string what = "slamdunk live session, " + source_->describe();
  OutputAttempts outputs(result.outputFailures);
  outputs.attempt(session_.trajectory, [&] {
    writeTumTrajectory(session_.trajectory, result.trajectory, what + ": every tracked frame");
  });
  outputs.attempt(session_.keyframes, [&] {
    writeTumTrajectory(session_.keyframes, result.keyframes, what + ": keyframes");
  });
  outputs.attempt(session_.map, [&] { CKeyframeGraphMap(result.graph).saveToFile(session_.map); });
  outputs.attempt(session_.gridMap, [&] {
    writeGridMap(GridMapBuilder(options_.slam.gridMap).build(*result.graph, sensorPose_),
                 session_.gridMap);
  });
  if (recorder_) {
    outputs.attempt(session_.recording, [&] { recorder_->finish(); });
    result.recorded = recorder_->written();
    result.recordSkipped = recorder_->skipped();
  }
  if (frameCsv_)
    outputs.attempt(session_.frameLog, [&] {
      frameCsv_->finish();
      frameCsvOutput_->commit();
    });
  return result;
}

}  // namespace slamdunk::live
