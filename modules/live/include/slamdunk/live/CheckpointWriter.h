#pragma once
// Crash-safe live sessions: every N new keyframes or S seconds (whichever comes first) a thread
// of its own writes the session so far to a checkpoint folder:
//
//   <folder>/map.map          the keyframe map (CKeyframeGraphMap): --load-map resumes from it
//   <folder>/trajectory.txt   every tracked frame so far (TUM, optical frame)
//   <folder>/keyframes.txt    the keyframes' poses (TUM)
//   <folder>/checkpoint.txt   what it holds: frames, keyframes, last frame time, when written
//   <folder>/gridmap.*        the occupancy grid (.gridmap, .png, .yaml), when asked for
//
// The folder is filled under a temporary name, flushed to disk (fsync) and swapped in at once
// (AtomicOutputFolder), so a process killed at any moment, or a power loss, leaves the previous
// checkpoint or the new one, complete. The tracking thread only counts frames; the writer
// takes a consistent copy of the graph (KeyframeGraph::snapshot, under the graph's read lock)
// and does the rest at a lower CPU priority.

#include <slamdunk/grid_map/GridMapOptions.h>
#include <slamdunk/live/FrameLog.h>
#include <slamdunk/live/LiveOptions.h>

#include <mrpt/poses/CPose3D.h>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace slamdunk::live {

/// The contents of checkpoint.txt ("key = value" lines).
struct CheckpointInfo {
  size_t sequence = 0;            ///< 1 for the session's first checkpoint, then 2, 3, ...
  size_t framesProcessed = 0;     ///< frames the session had processed when it was taken
  size_t framesTracked = 0;       ///< of those, tracked (the lines of trajectory.txt)
  size_t keyframes = 0;           ///< keyframes in map.map
  double lastFrameTimestamp = 0;  ///< the last processed frame's timestamp (s)
  double unixTime = 0;            ///< wall-clock time (s since 1970) when it was taken
  /// With a grid asked for (setGridMap): "gridmap.gridmap" when the folder holds it, else why
  /// not (early in a session the camera may not have seen the floor yet). Empty otherwise.
  std::string gridMap;

  /// Reads <folder>/checkpoint.txt; throws std::runtime_error naming the file when it is
  /// missing or malformed.
  static CheckpointInfo read(const std::string& folder);
};

/// Cost and count of the checkpoints of a session (for its summary).
struct CheckpointFigures {
  size_t written = 0;
  std::vector<double> snapshotMs;  ///< copying the graph (holds the graph's read lock)
  std::vector<double> totalMs;     ///< snapshot, serialization, compression, fsync, swap
  std::string folder;
  std::string error;  ///< the first failure; later checkpoints are still tried
};

class CheckpointWriter {
 public:
  static constexpr const char* kMapFile = "map.map";
  static constexpr const char* kTrajectoryFile = "trajectory.txt";
  static constexpr const char* kKeyframesFile = "keyframes.txt";
  static constexpr const char* kInfoFile = "checkpoint.txt";
  static constexpr const char* kGridMapPrefix = "gridmap";

  /// Checks that the folder's parent exists (std::runtime_error otherwise); the thread starts
  /// with start(). `description` goes into the trajectory files' header.
  CheckpointWriter(const CheckpointOptions& options, std::string folder,
                   std::shared_ptr<const KeyframeGraph> graph, FrameLog& frames,
                   std::string description);
  ~CheckpointWriter();  ///< stop()
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  /// Each checkpoint also holds the occupancy grid of its map (gridmap.*). Before start().
  void setGridMap(const GridMapOptions& options) { gridMap_ = options; }
  /// The camera's pose on the robot (the observations' sensorPose), for the grid's floor.
  void setSensorPose(const mrpt::poses::CPose3D& sensorPose);
  void start();
  /// Tracking thread, after each frame: two atomic counters, and a wake-up when a keyframe
  /// makes a checkpoint due.
  void frameProcessed(bool tracked, bool newKeyframe);
  /// Ends the thread, after the checkpoint being written, if any.
  void stop();
  /// Writes a checkpoint now, on the calling thread (tests, and callers that want one).
  void writeNow();

  CheckpointFigures figures() const;
  const std::string& folder() const { return folder_; }

 private:
  void writerLoop();
  bool dueByKeyframes() const;
  void write();

  const CheckpointOptions options_;
  const std::string folder_, description_;
  const std::shared_ptr<const KeyframeGraph> graph_;
  FrameLog& frames_;
  std::optional<GridMapOptions> gridMap_;
  std::optional<mrpt::poses::CPose3D> sensorPose_;  // guarded by mutex_

  std::atomic<size_t> processed_{0}, tracked_{0}, newKeyframes_{0};
  std::atomic<size_t> keyframesAtLast_{0};  ///< newKeyframes_ at the last checkpoint
  std::atomic<size_t> processedAtLast_{0};  ///< processed_ at the last checkpoint

  std::mutex writeMutex_;           // one checkpoint at a time (writer thread, writeNow())
  SessionLog<FrameRecord> copied_;  ///< the frame records seen so far (under writeMutex_)

  mutable std::mutex mutex_;  // guards stopping_, figures_ and sensorPose_
  std::condition_variable wake_;
  bool stopping_ = false;
  CheckpointFigures figures_;
  std::thread thread_;
};

}  // namespace slamdunk::live
