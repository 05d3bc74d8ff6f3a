#pragma once
// SlamDunk on a live RGB-D stream, for embedding in an application (a robot's, or
// slamdunk-live itself). Four threads: a grabber (the frame source, optional recording), the
// tracker (SlamSystem::process on the latest frames: when it falls behind, the oldest waiting
// frame is dropped and counted), the local optimizer (SlamSystem's own thread) and, unless
// turned off, a checkpoint writer that saves the trajectory and map every few keyframes or
// seconds so that a killed process loses at most one interval. The caller's thread is free.
//
//   #include <slamdunk/live/LiveSlam.h>
//   using namespace slamdunk::live;
//
//   LiveSession session;
//   session.trajectory = "run.txt";              // outputs, written by finish()
//   auto live = LiveSlam::fromIniFile("live.ini", session);    // camera or replay from the INI
//   live->onPose([](const LivePose& p) { ... });  // optional: every frame, tracking thread
//   live->start();
//   while (robotRunning) {
//     const LivePose p = live->latestPose();      // or poll: optical and MRPT sensor frames
//     ...
//   }
//   const LiveResult result = live->finish();     // stops, finishes the map, writes outputs
//
// Sources: the INI's source section (LiveSlam::fromIniFile), or any FrameSource given to the
// constructor: a SensorFrameSource around an mrpt::hwdrivers::CGenericSensor the application
// owns, a PushFrameSource the application feeds with push(obs), a ReplayFrameSource.
// Frames: see LivePose. Signals are the application's business: call requestStop() from its
// own handler's flag (slamdunk-live does so on SIGINT/SIGTERM).

#include <slamdunk/live/CheckpointWriter.h>
#include <slamdunk/live/FrameLog.h>
#include <slamdunk/live/FrameSource.h>
#include <slamdunk/live/LiveOptions.h>
#include <slamdunk/live/LivePipeline.h>
#include <slamdunk/live/LivePose.h>
#include <slamdunk/live/RawlogRecorder.h>

#include <slamdunk/slam/FrameCsvLog.h>
#include <slamdunk/slam/SlamSystem.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk::live {

/// What a session starts from and writes. Every output is optional and written atomically.
struct LiveSession {
  /// Continue mapping in a saved map (CKeyframeGraphMap::loadFromFile(path)->graph(), e.g. a
  /// checkpoint's map.map): the camera relocalizes in it and poses are in its world. Null: a
  /// new map.
  std::shared_ptr<KeyframeGraph> startMap;
  std::string trajectory;  ///< TUM file of every tracked frame
  std::string keyframes;   ///< TUM file of the keyframes; "" = "<trajectory>_keyframes<ext>"
  std::string map;         ///< the keyframe map (CKeyframeGraphMap)
  std::string recording;   ///< rawlog of every received frame, images embedded
  std::string frameLog;    ///< CSV, one line per processed frame (FrameCsvLog)
  /// PREFIX of the occupancy grid (PREFIX.gridmap, .png, .yaml; options: [grid_map]), written at
  /// the end; each checkpoint then holds the grid of its map too.
  std::string gridMap;
  size_t maxFrames = 0;  ///< stop after receiving this many frames; 0 = no limit
  /// Localization only in startMap ([tracker] localization_only): the map is not changed.
  bool localizationOnly = false;
  /// With localizationOnly: keyframes where the map covers too little ([tracker] extend_map).
  bool extendMap = false;
};

/// Everything a finished session measured and built.
struct LiveResult {
  LiveCounters counters;
  SlamStatistics stats;
  std::vector<double> latenciesMs;  ///< per processed frame, grab to pose
  Trajectory trajectory;            ///< tracked frames, optical frame, after the last optimization
  Trajectory keyframes;
  std::shared_ptr<KeyframeGraph> graph;
  bool stopRequested = false;  ///< ended by requestStop(), not by the end of the stream
  /// The source's error that ended the session early (the outputs cover the frames before it).
  std::string sourceError;
  std::optional<size_t> recorded, recordSkipped;  ///< with a recording
  std::optional<CheckpointFigures> checkpoints;   ///< with checkpoints on
  std::string callbackError;  ///< the first exception thrown by an onPose/onFrame callback
  GraphMemory mapMemory;      ///< the keyframe graph's data at the end, counted directly
  /// Outputs that could not be written, each message naming the file and why (each was
  /// written atomically: its earlier version is kept). A session cannot be repeated, so every
  /// other output is still written.
  std::vector<std::string> outputFailures;
};

class LiveSlam {
 public:
  using PoseCallback = std::function<void(const LivePose&)>;
  using FrameCallback =
      std::function<void(const mrpt::obs::CObservation3DRangeScan&, const TrackingResult&)>;

  /// The source, pipeline and checkpoints of a live INI (see LiveOptions). Throws
  /// std::runtime_error naming the file and what is wrong, or an output folder that does not
  /// exist.
  static std::unique_ptr<LiveSlam> fromIniFile(const std::string& path,
                                               const LiveSession& session = {},
                                               const SourceOverrides& overrides = {});
  /// Any source. Throws std::runtime_error when an output's folder does not exist or cannot be
  /// written.
  LiveSlam(LiveOptions options, std::unique_ptr<FrameSource> source, LiveSession session = {});
  /// Stops the threads without writing anything (finish() writes).
  ~LiveSlam();
  LiveSlam(const LiveSlam&) = delete;
  LiveSlam& operator=(const LiveSlam&) = delete;

  /// Called after every frame on the tracking thread, before the next frame is taken: keep
  /// them short (copy, signal another thread). Exceptions are caught and reported in
  /// LiveResult::callbackError. Set before start().
  void onPose(PoseCallback callback);
  void onFrame(FrameCallback callback);

  /// Starts the threads; the source opens on the grabber thread.
  void start();
  /// Waits until the source is open (true), it failed (throws its error), `timeoutSeconds`
  /// passed or `*cancel` became true (false).
  bool waitUntilOpen(double timeoutSeconds, const std::atomic<bool>* cancel = nullptr);

  /// The pose of the last processed frame (valid = false before the first).
  LivePose latestPose() const;
  LiveCounters counters() const;
  /// The source ended (or failed) and every frame received was processed.
  bool finished() const;
  /// The grabber stops; the frames already received are still processed. Any thread.
  void requestStop();
  /// Stops (unless the source already ended), waits for the frames received, finishes the
  /// optimization, writes the session's outputs and returns the results (outputs that cannot
  /// be written are listed in LiveResult::outputFailures). Throws std::runtime_error when no
  /// frame was processed because the source failed or delivered none (nothing is written then).
  LiveResult finish();

  const FrameSource& source() const { return *source_; }
  const LiveOptions& options() const { return options_; }
  /// The map being built (thread-safe to read while the session runs).
  std::shared_ptr<const KeyframeGraph> graph() const { return slam_->graph(); }
  /// Where checkpoints go ("" when they are off or have no place: no folder, no trajectory).
  std::string checkpointFolder() const;
  /// The checkpoints written so far (none when they are off). Any thread.
  std::optional<CheckpointFigures> checkpointFigures() const;

 private:
  void frameDone(const mrpt::obs::CObservation3DRangeScan& frame, const TrackingResult& r,
                 double latencyMs);
  void callbackFailed(const char* which, const std::exception& e);

  LiveOptions options_;
  std::unique_ptr<FrameSource> source_;
  LiveSession session_;
  std::unique_ptr<SlamSystem> slam_;
  std::unique_ptr<RawlogRecorder> recorder_;
  FrameLog frameLog_;
  std::unique_ptr<AtomicOutput> frameCsvOutput_;
  std::unique_ptr<FrameCsvLog> frameCsv_;
  std::unique_ptr<CheckpointWriter> checkpoints_;
  /// Of the first frame, set by the tracking thread; read once the pipeline has ended.
  std::optional<mrpt::poses::CPose3D> sensorPose_;
  std::unique_ptr<LivePipeline> pipeline_;
  PoseCallback poseCallback_;
  FrameCallback frameCallback_;

  mutable std::mutex poseMutex_;  // guards latest_ and callbackError_
  LivePose latest_;
  std::string callbackError_;
  std::atomic<bool> stopRequested_{false};
  bool started_ = false, finished_ = false;
};

}  // namespace slamdunk::live
