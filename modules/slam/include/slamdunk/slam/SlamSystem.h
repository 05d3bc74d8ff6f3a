#pragma once
// The SlamDunk pipeline for one camera: tracking, keyframe graph, local optimization (inline or
// in its own thread), and every frame's pose kept relative to its reference keyframe so that
// optimization moves the whole trajectory.

#include <slamdunk/core/SessionLog.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/features/FramePreparation.h>
#include <slamdunk/loop_closing/LoopClosing.h>
#include <slamdunk/optimization/LocalOptimization.h>
#include <slamdunk/slam/SlamOptions.h>
#include <slamdunk/tracking/Tracker.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <atomic>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

namespace slamdunk {

/// What happened to one input frame, with its pose stored relative to a keyframe.
struct FrameRecord {
  double timestamp = 0;
  TrackingStatus status = TrackingStatus::Lost;
  KeyframeId reference = 0;
  Pose poseInReference = Pose::Identity();
};

/// A frame record in a SessionLog's file: the stamp, the status, the keyframe and the pose's
/// 3 x 4 matrix, bit for bit (a trajectory written from the file is the one in memory).
template <>
struct SessionLogCodec<FrameRecord> {
  static constexpr size_t kStatusAt = sizeof(double);
  static constexpr size_t kReferenceAt = kStatusAt + 1;
  static constexpr size_t kPoseAt = kReferenceAt + sizeof(KeyframeId);
  static constexpr size_t kBytes = kPoseAt + 12 * sizeof(double);
  static void encode(const FrameRecord& r, unsigned char* out) {
    std::memcpy(out, &r.timestamp, sizeof(double));
    out[kStatusAt] = static_cast<unsigned char>(r.status);
    std::memcpy(out + kReferenceAt, &r.reference, sizeof(KeyframeId));
    const Eigen::Matrix<double, 3, 4> m = r.poseInReference.matrix().topRows<3>();
    std::memcpy(out + kPoseAt, m.data(), kBytes - kPoseAt);
  }
  static FrameRecord decode(const unsigned char* in) {
    FrameRecord r;
    std::memcpy(&r.timestamp, in, sizeof(double));
    r.status = static_cast<TrackingStatus>(in[kStatusAt]);
    std::memcpy(&r.reference, in + kReferenceAt, sizeof(KeyframeId));
    Eigen::Matrix<double, 3, 4> m;
    std::memcpy(m.data(), in + kPoseAt, kBytes - kPoseAt);
    r.poseInReference.matrix().topRows<3>() = m;
    return r;
  }
};

/// Hands each tracked frame's pose, through its reference keyframe's pose in `graph`, to
/// `visit` (a frame whose keyframe is not in the graph is left out, like a lost one); returns
/// how many. One at a time: a long session's trajectory is never held whole a second time.
size_t forEachTrackedPose(const SessionLog<FrameRecord>& records, const KeyframeGraph& graph,
                          const std::function<void(double, const Pose&)>& visit);

/// Replaces the poses of frames the tracker estimated again (TrackingResult::revisedFrames),
/// found by their stamps among the newest records (the tracker revises the frames just before
/// the one it reports them with, eight at most). Returns how many were replaced: a record no
/// longer in memory (gone to the log's file at a chunk's end) keeps its first pose.
size_t reviseFrameRecords(SessionLog<FrameRecord>& records,
                          const std::vector<TrackingResult::RevisedFrame>& revised);

struct SlamStatistics {
  size_t frames = 0, tracked = 0, lost = 0, loopClosures = 0;
  LoopClosingStatistics placeLoops;  ///< loops closed by place recognition beyond the window
  size_t keyframes = 0;              ///< in the map: made and not culled
  size_t keyframesCulled = 0;        ///< made, then culled as redundant (KeyframeCulling)
  size_t trackedDepthOnly = 0;       ///< of the tracked frames, those registered by depth alone
  size_t optimizations = 0;
  size_t relocalizations = 0;  ///< frames registered against the whole map after being lost
  /// Times a session from a saved map, not relocalized in it, started a new component of the
  /// map (its joins with the rest are placeLoops.joins).
  size_t componentsStarted = 0;
  /// Localization only: tracked frames whose view the map covers too little (TrackingResult::
  /// outsideMap).
  size_t framesOutsideMap = 0;
  /// Frames not processed because their timestamp was not after the previous frame's (a
  /// repeated or backward stamp), and the first few reasons, each naming the frame.
  size_t framesOutOfOrder = 0;
  std::vector<std::string> outOfOrderExamples;
  SessionLog<StageTimings> stageTimings;  ///< one per processed frame (tracking only)
  std::vector<double> optimizationMs;     ///< one per local optimization
  double maxOptimizationTranslation = 0;  ///< metres: largest pose change by any optimization
  double maxOptimizationRotationDeg = 0;
  std::vector<std::string> lostReasons;  ///< distinct reasons, first occurrence order
  PoolPreparationStats poolPreparation;  ///< Local Mapping's background index builds
  /// What the tracker learned of the camera (or the INI's values where it learns nothing).
  double rollingShutterMs = 0;
  DepthNoiseModel keypointNoise;
};

class SlamSystem {
 public:
  explicit SlamSystem(const SlamOptions& options, std::shared_ptr<KeyframeGraph> graph = nullptr);
  ~SlamSystem();  ///< stops the optimization thread
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;

  /// Builds the frame from the observation; a malformed observation (no depth, sizes that
  /// disagree, ...) is reported as a lost frame with the reason, never thrown.
  /// A frame whose timestamp is not after the last processed frame's (repeated, or going
  /// backwards) is skipped: result.skipped, status Lost, the reason naming both frames; it is
  /// neither tracked nor counted lost, so the trajectory's stamps always increase.
  TrackingResult process(const mrpt::obs::CObservation3DRangeScan& obs);
  TrackingResult process(const RgbdFrame& frame);
  /// The same for a frame prepared ahead (FramePrefetcher with options().features): its
  /// features are not extracted again, and the result is the one process(obs) gives.
  TrackingResult process(PreparedFrame prepared);

  /// Waits for pending optimizations, then runs the final global pass if enabled, and holds
  /// the map in the first camera's frame (not when localizing only: the map stays as loaded).
  void finish();

  /// Poses of all tracked frames (lost ones are left out), through their reference keyframe.
  Trajectory trajectory() const;
  Trajectory keyframeTrajectory() const;
  const SessionLog<FrameRecord>& frames() const { return frames_; }
  SlamStatistics statistics() const;
  const std::shared_ptr<KeyframeGraph>& graph() const { return graph_; }
  const SlamOptions& options() const { return options_; }
  /// The camera maps a component not joined to the map's first keyframe: its poses are in that
  /// component's own frame (TrackerOptions::newComponentAfter) until a join.
  /// As of the last frame process() returned: call it from the thread that calls process().
  bool inSeparateComponent() const { return separateComponent_; }

 private:
  /// The local optimizations hold the newest keyframe where no ring is held fixed (early in a
  /// map), so the first keyframe, where the camera started, drifts off the origin (about 1 cm
  /// and 0.1° on CI's sessions). The whole map moves back rigidly, once at the end: its frame is
  /// the first camera's again, the frame a session joined to it later is placed in.
  void holdTheMapInTheFirstCameraFrame();
  /// The skip result for a frame whose timestamp does not increase, or nullopt.
  std::optional<TrackingResult> outOfOrder(double timestamp);
  /// Tracks the frame, with its features when they were extracted already.
  TrackingResult track(const RgbdFrame& frame, PreparedFrame* prepared = nullptr);
  /// The result of an observation no frame can be made of (counted as lost).
  TrackingResult unusable(double timestamp, const std::string& why);
  /// After the local optimization around a new keyframe, on its thread: place recognition,
  /// and the correction of the loops it accepts.
  void closeLoops(KeyframeId keyframe, const DepthNoiseModel& noise);

  SlamOptions options_;
  std::shared_ptr<KeyframeGraph> graph_;
  Tracker tracker_;
  /// One record per frame, for as long as the session runs (the newest in memory, the rest in
  /// the log's temporary file: constant memory however long the session).
  SessionLog<FrameRecord> frames_;
  SlamStatistics stats_;
  size_t framesGiven_ = 0;         ///< every call of process(), skipped frames included
  size_t lastProcessedIndex_ = 0;  ///< of the last frame not skipped
  std::optional<double> lastProcessedTimestamp_;
  bool separateComponent_ = false;  ///< as of the last frame tracked
  /// Whether the newest keyframe was still apart from the first after the last correction (the
  /// back end's finding, which the tracker's next frame makes its own).
  std::atomic<bool> apartAfterCorrection_{false};

  mutable std::mutex statsMutex_;
  /// Held while the tracker processes a frame, and by the back end while it writes a loop
  /// correction: a frame is registered in one map, before the correction or after it.
  std::mutex frameMutex_;
  std::unique_ptr<LoopClosing> loopClosing_;  ///< null when [loop_closing] enabled = false
  /// After the tracker and loop closing: it is stopped first, and tells the tracker of every
  /// optimization and correction.
  LocalOptimization optimization_;
};

}  // namespace slamdunk
