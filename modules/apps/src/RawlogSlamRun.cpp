#include <slamdunk/apps/RawlogSlamRun.h>

#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/dense/DenseOutputs.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/features/FramePreparation.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SimpleMapExport.h>

#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace slamdunk::apps {

namespace {

/// Writes output `target` through `write(stagedPath)`; a failure names the target and why it may
/// have failed (free space, file size limit).
template <class Write>
void writeStaged(const std::string& target, const std::string& staged, Write write) {
  try {
    write(staged);
  } catch (const std::exception& e) {
    throw std::runtime_error(writeErrorMessage(target, e.what(), staged));
  }
}

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char buf[1024];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

}  // namespace

RawlogSlamRun::RawlogSlamRun(RawlogRunOptions options) : options_(std::move(options)) {
  RawlogRunOptions& o = options_;
  if (o.trajectory.empty()) throw std::invalid_argument("RawlogSlamRun: no trajectory output");
  const bool keyframesGiven = !o.keyframes.empty();
  if (!keyframesGiven) o.keyframes = keyframeTrajectoryPathFor(o.trajectory);
  if (!o.dense.empty() || !o.render.empty() || !o.simpleMap.empty())
    o.slam.tracker.keepKeyframeImages = true;  // what these outputs are made of
  rejectPathClashes({{"IN.rawlog", o.rawlog},
                     {"--config", o.configFile},
                     {"--gt", o.groundTruth},
                     {"--load-map", o.startMap}},
                    {{"--trajectory", o.trajectory},
                     {keyframesGiven ? "--keyframes" : "the keyframe trajectory", o.keyframes},
                     {"--save-map", o.map},
                     {"--render", o.render},
                     {"--simplemap", o.simpleMap},
                     {"--frame-log", o.frameLog},
                     {"--gridmap", o.gridMap.empty() ? "" : o.gridMap + ".gridmap"},
                     {"--gridmap", o.gridMap.empty() ? "" : o.gridMap + ".png"},
                     {"--gridmap", o.gridMap.empty() ? "" : o.gridMap + ".yaml"}});
  // Fail on unwritable outputs before spending minutes on the run.
  for (const std::string& out :
       {o.trajectory, o.keyframes, o.map, o.dense, o.render, o.simpleMap, o.frameLog, o.gridMap})
    if (!out.empty()) requireWritableFolder(out);
  if (!o.groundTruth.empty()) groundTruth_ = readTumTrajectory(o.groundTruth);
  if (!o.frameLog.empty()) {
    frameLogStaged_ = outputs_.stage(o.frameLog);
    writeStaged(o.frameLog, frameLogStaged_,
                [&](const std::string& path) { frameLog_ = std::make_unique<FrameCsvLog>(path); });
  }
  std::shared_ptr<KeyframeGraph> startMap;
  if (!o.startMap.empty()) {
    startMap = CKeyframeGraphMap::loadFromFile(o.startMap)->graph();
    say(format("[slamdunk-rawlog] loaded map '%s': %zu keyframes, %zu edges", o.startMap.c_str(),
               startMap->keyframeCount(), startMap->edgeCount()));
  }
  reader_ = std::make_unique<PrefetchingRawlogReader>(
      o.rawlog, PrefetchingRawlogReader::kDefaultDepth, o.firstFrame);
  slam_ = std::make_unique<SlamSystem>(o.slam, startMap);
}

RawlogSlamRun::~RawlogSlamRun() = default;

void RawlogSlamRun::say(const std::string& line) const {
  if (options_.log) options_.log(line);
}

RawlogRunResult RawlogSlamRun::run() {
  if (ran_) throw std::logic_error("RawlogSlamRun::run() called twice");
  ran_ = true;
  RawlogRunResult result;
  RunFigures& fig = result.figures;
  const auto start = SteadyClock::now();
  result.readError = processFrames(fig);
  const std::string& in = options_.rawlog;
  if (!result.readError.empty() && fig.decodeMs.empty()) throw std::runtime_error(result.readError);
  if (reader_->entriesRead() > 0 && fig.decodeMs.empty())
    throw std::runtime_error("rawlog '" + in + "' has no CObservation3DRangeScan (" +
                             std::to_string(reader_->otherObservationsSkipped()) +
                             " other observations)");
  if (fig.decodeMs.empty()) throw std::runtime_error("rawlog '" + in + "' is empty");
  slam_->finish();
  fig.wallSeconds = msSince(start) / 1000.0 - pausedSeconds_;
  fig.stats = slam_->statistics();
  fig.edges = slam_->graph()->edgeCount();
  fig.mapMemory = slam_->graph()->memory();
  fig.peakRssKiB = peakResidentKiB();

  const Trajectory trajectory = slam_->trajectory();
  if (!groundTruth_.empty()) {
    fig.ate = evaluateAte(groundTruth_, trajectory);
    if (!fig.ate)
      say(format("slamdunk-rawlog: only %zu tracked frames: no ATE", trajectory.size()));
  }
  writeOutputs(trajectory);
  if (!options_.map.empty()) say("[slamdunk-rawlog] map written to " + options_.map);
  if (!options_.render.empty())
    say("[slamdunk-rawlog] picture written to " + options_.render + " (and its .3Dscene)");
  return result;
}

std::string RawlogSlamRun::processFrames(RunFigures& fig) {
  const auto start = SteadyClock::now();
  // Frames are built and their features extracted a frame or two ahead, on a thread of their
  // own: they depend on the observation alone, and the tracking thread goes on registering.
  FramePrefetcher frames([&] { return reader_->next(); }, options_.slam.features);
  for (;;) {
    const auto t = SteadyClock::now();
    std::optional<PreparedFrame> prepared;
    try {
      prepared = frames.next();
    } catch (const std::exception& e) {
      // A recording cut short keeps the frames before the damage: they are processed and
      // written, and the caller still hears of the problem.
      return e.what();
    }
    if (!prepared) return {};
    const double decodeMs = msSince(t);
    if (pauseCallback_) {
      const auto paused = SteadyClock::now();
      pauseCallback_(fig.decodeMs.size());
      pausedSeconds_ += msSince(paused) / 1000.0;
    }
    const mrpt::obs::CObservation3DRangeScan::Ptr obs = prepared->observation;
    if (!sensorPose_) sensorPose_ = obs->sensorPose;  // on a robot: the grid's floor
    const TrackingResult r = slam_->process(std::move(*prepared));
    if (frameCallback_) frameCallback_(*obs, r);
    obs->unload();
    fig.decodeMs.push_back(decodeMs);
    const size_t n = fig.decodeMs.size();
    frameDone(r, n - 1, fig);
    if (n % 100 == 0)
      say(format("[slamdunk-rawlog] %zu frames, %zu keyframes, %.1f frames/s", n,
                 slam_->graph()->keyframeCount(), n / (msSince(start) / 1000.0)));
    if (options_.maxFrames && n >= options_.maxFrames) return {};
  }
}

void RawlogSlamRun::frameDone(const TrackingResult& r, size_t index, RunFigures& fig) {
  if (frameLog_) frameLog_->add(r);
  if (fig.firstTrackedFrame < 0 && r.status != TrackingStatus::Lost)
    fig.firstTrackedFrame = static_cast<long>(index);
  if (r.skipped) {
    // Warned about, a few times: a clock reset can put every later frame behind.
    if (++skippedWarnings_ <= 10)
      say("[slamdunk-rawlog] warning: " + r.lostReason +
          (skippedWarnings_ == 10 ? " (further such warnings not shown)" : ""));
  } else if (r.status == TrackingStatus::Lost) {
    say(format("frame %zu (t=%.6f): lost: %s", index, r.timestamp, r.lostReason.c_str()));
  }
}

void RawlogSlamRun::writeOutputs(const Trajectory& trajectory) {
  const RawlogRunOptions& o = options_;
  writeStaged(o.trajectory, outputs_.stage(o.trajectory), [&](const std::string& staged) {
    writeTumTrajectory(staged, trajectory, "slamdunk-rawlog " + o.rawlog + ": every tracked frame");
  });
  writeStaged(o.keyframes, outputs_.stage(o.keyframes), [&](const std::string& staged) {
    writeTumTrajectory(staged, slam_->keyframeTrajectory(),
                       "slamdunk-rawlog " + o.rawlog + ": keyframes");
  });
  if (frameLog_)
    writeStaged(o.frameLog, frameLogStaged_, [&](const std::string&) { frameLog_->finish(); });
  const KeyframeGraph& graph = *slam_->graph();
  if (!o.map.empty())
    writeStaged(o.map, outputs_.stage(o.map), [&](const std::string& staged) {
      CKeyframeGraphMap(slam_->graph()).saveToFile(staged);
    });
  if (!o.dense.empty()) {
    const std::string staged = outputs_.stagePrefix(o.dense, {".ply", ".pcd", ".ot", ".bt"});
    writeStaged(o.dense, staged, [&](const std::string&) {
      const auto d = writeDenseOutputs(graph, staged);
      say(
          format("[slamdunk-rawlog] dense cloud of %zu points and OctoMap (%zu occupied voxels) "
                 "for %s.{ply,pcd,ot,bt}",
                 d.cloudPoints, d.occupancy.occupiedLeaves, o.dense.c_str()));
    });
  }
  if (!o.render.empty()) {
    const std::filesystem::path png(o.render);
    const std::string scene = (png.parent_path() / (png.stem().string() + ".3Dscene")).string();
    const std::string stagedPng = outputs_.stage(o.render), stagedScene = outputs_.stage(scene);
    writeStaged(o.render, stagedPng, [&](const std::string&) {
      try {
        renderKeyframeGraph(graph, trajectory, stagedPng, stagedScene);
      } catch (const std::exception& e) {
        throw std::runtime_error(withTargetName(e.what(), stagedScene, scene));
      }
    });
  }
  if (!o.gridMap.empty()) {
    const std::string staged = outputs_.stagePrefix(o.gridMap, gridMapExtensions());
    writeStaged(o.gridMap, staged, [&](const std::string&) {
      const auto start = SteadyClock::now();
      const GridMap grid = GridMapBuilder(o.slam.gridMap).build(graph, sensorPose_);
      const double ms = msSince(start);
      writeGridMap(grid, staged, std::filesystem::path(o.gridMap + ".png").filename().string());
      say(
          format("[slamdunk-rawlog] occupancy grid of %u x %u cells of %.2f m (%zu occupied, "
                 "%zu free), made in %.0f ms, for %s.{gridmap,png,yaml}",
                 grid.grid.getSizeX(), grid.grid.getSizeY(), grid.grid.getResolution(),
                 grid.occupiedCells, grid.freeCells, ms, o.gridMap.c_str()));
    });
  }
  if (!o.simpleMap.empty())
    writeStaged(o.simpleMap, outputs_.stage(o.simpleMap),
                [&](const std::string& staged) { exportSimpleMap(graph, staged); });
  outputs_.commit();
}

}  // namespace slamdunk::apps
