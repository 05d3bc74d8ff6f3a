#pragma once
// SlamDunk over a recorded rawlog with every output of slamdunk-rawlog, for an application to
// do what the program does (as MRPT 2.x's mrpt::apps::ICP_SLAM_App_Rawlog does for icp-slam);
// slamdunk-rawlog is a command line over it.
//
//   #include <slamdunk/apps/RawlogSlamRun.h>
//   using namespace slamdunk::apps;
//
//   RawlogRunOptions options;
//   options.rawlog = "in.rawlog";
//   options.trajectory = "out.txt";               // and any other output below
//   RawlogSlamRun run(options);                   // checks the inputs and output folders
//   run.onFrame([](const auto& obs, const slamdunk::TrackingResult& r) { ... });  // optional
//   const RawlogRunResult result = run.run();     // processes, writes every output
//   printRunSummary(result.figures, false);
//
// The rawlog is decoded a few frames ahead on a thread of its own, and each frame's features
// are extracted ahead on another (FramePrefetcher); frames are tracked on the caller's thread,
// in order, so a run's outputs do not depend on timing.

#include <slamdunk/apps/RunSummary.h>
#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/slam/FrameCsvLog.h>
#include <slamdunk/slam/SlamSystem.h>

#include <mrpt/poses/CPose3D.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace slamdunk::apps {

struct RawlogRunOptions {
  std::string rawlog;  ///< CObservation3DRangeScan; other observations are skipped
  SlamOptions slam;
  std::string configFile;   ///< the INI `slam` was read from, if any: no output may replace it
  std::string groundTruth;  ///< TUM file: the figures get the ATE against it
  /// A saved map (CKeyframeGraphMap) to continue: the camera relocalizes in it, then mapping
  /// goes on, poses in its world.
  std::string startMap;
  size_t firstFrame = 0;  ///< range scans before this index are skipped
  size_t maxFrames = 0;   ///< process at most this many; 0 = all

  /// Outputs: all of them are replaced together at the end of a run, or none (StagedOutputs).
  std::string trajectory;  ///< TUM file of every tracked frame; required
  std::string keyframes;   ///< TUM file of the keyframes; "" = "<trajectory>_keyframes<ext>"
  std::string map;         ///< the keyframe map (CKeyframeGraphMap)
  std::string dense;       ///< PREFIX of PREFIX.ply, .pcd (coloured cloud), .ot, .bt (OctoMap)
  std::string render;      ///< PNG of the map, rendered offscreen; a .3Dscene beside it
  std::string simpleMap;   ///< keyframes as an MRPT .simplemap
  /// PREFIX of the 2D occupancy grid: PREFIX.gridmap (MRPT), PREFIX.png and PREFIX.yaml (ROS
  /// map_server); its options are slam.gridMap ([grid_map])
  std::string gridMap;
  std::string frameLog;  ///< CSV, one line per frame (FrameCsvLog)

  /// Progress, warnings and lost frames, one line each; empty: silent.
  std::function<void(const std::string&)> log;
};

struct RawlogRunResult {
  RunFigures figures;
  /// The rawlog was damaged after some frames: they were processed and the outputs cover them.
  std::string readError;
};

class RawlogSlamRun {
 public:
  using FrameCallback =
      std::function<void(const mrpt::obs::CObservation3DRangeScan&, const TrackingResult&)>;
  /// Called before each frame with the number of frames processed so far. The time spent in it
  /// (a viewer's pause) is not part of the run's speed.
  using PauseCallback = std::function<void(size_t framesDone)>;

  /// Opens the rawlog, reads the ground truth and the start map. Throws std::invalid_argument
  /// when an output would replace an input or another output (messages name the paths by
  /// slamdunk-rawlog's options), std::runtime_error naming the file for anything unreadable or
  /// an output folder that cannot be written.
  explicit RawlogSlamRun(RawlogRunOptions options);
  ~RawlogSlamRun();
  RawlogSlamRun(const RawlogSlamRun&) = delete;
  RawlogSlamRun& operator=(const RawlogSlamRun&) = delete;

  /// Each after the frame is processed, on the caller's thread; set before run().
  void onFrame(FrameCallback callback) { frameCallback_ = std::move(callback); }
  void beforeFrame(PauseCallback callback) { pauseCallback_ = std::move(callback); }

  /// Processes the rawlog, finishes the map and writes every output. Once. Throws
  /// std::runtime_error when no frame could be processed or an output cannot be written (every
  /// earlier file of the user's is then kept).
  RawlogRunResult run();

  /// The map being built (thread-safe to read while the run goes on, e.g. by a viewer).
  std::shared_ptr<const KeyframeGraph> graph() const { return slam_->graph(); }
  const RawlogRunOptions& options() const { return options_; }

 private:
  /// Reads and processes the frames; returns the read error that ended the rawlog early.
  std::string processFrames(RunFigures& fig);
  void frameDone(const TrackingResult& r, size_t index, RunFigures& fig);
  void writeOutputs(const Trajectory& trajectory);
  void say(const std::string& line) const;

  RawlogRunOptions options_;
  Trajectory groundTruth_;
  StagedOutputs outputs_;
  std::string frameLogStaged_;
  std::unique_ptr<FrameCsvLog> frameLog_;
  std::unique_ptr<PrefetchingRawlogReader> reader_;
  std::unique_ptr<SlamSystem> slam_;
  FrameCallback frameCallback_;
  PauseCallback pauseCallback_;
  double pausedSeconds_ = 0;  ///< in beforeFrame
  size_t skippedWarnings_ = 0;
  std::optional<mrpt::poses::CPose3D> sensorPose_;  ///< of the first frame processed
  bool ran_ = false;
};

}  // namespace slamdunk::apps
