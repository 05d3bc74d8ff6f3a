#pragma once
// Local Mapping (paper Sec. 4.1 and Fig. 2): keyframe positions in a quadtree over the
// ground-parallel plane, the active window of side W around a camera pose, the feature pool
// built from it, and the shift of the window when the camera moves more than T from its centre.
//
// Pools are prepared off the tracking thread. A request snapshots the window (keyframes and
// their poses, a cheap copy of pointers) and a worker thread builds its index; the tracker keeps
// matching against the current pool until the new one is handed over. A new keyframe gets a
// small index of its own, handed over on the next frame, so the camera is matched against it
// long before the window around it is ready.
//
// Hand-over: with handoverFrames > 0, a pool asked for at frame i replaces the current one at a
// frame fixed by the request alone, i + 1 + (window features / handoverFeaturesPerFrame) up to
// i + handoverFrames (a keyframe's own index at i + 1), waiting there if it is not ready:
// offline runs are deterministic. With 0 it is handed over as soon as it is ready
// and tracking never waits (live).

#include <slamdunk/mapping/FeaturePool.h>
#include <slamdunk/mapping/QuadTree.h>

#include <mrpt/config/CLoadableOptions.h>

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

namespace slamdunk {

struct LocalMapOptions : public mrpt::config::CLoadableOptions {
  double windowSize = 5.0;    ///< W: side of the active window square, metres
  double windowShift = 0.25;  ///< T: move the window when the camera is this far from its centre
  /// ... or has turned this many degrees from the orientation the window was asked for (0 =
  /// never, the paper's translation-only test). The pool's frustum filter keeps what that
  /// orientation sees: a camera turning (or walking a mapped room again) without a keyframe to
  /// move the window would see less and less of its pool and spawn keyframes where the map
  /// already has them. At most the angle of the frustum's margin (0.1 of a 640-px image at
  /// 525 px focal length: 7 degrees), so that what comes into view is still in the pool.
  double windowShiftAngle = 7.0;
  /// Build pools on a worker thread (false: inside the tracking call, as in the paper).
  bool backgroundPreparation = true;
  /// Most frames between asking for a window's pool and using it (0 = as soon as it is ready).
  int handoverFrames = 8;
  /// A window is handed over one frame after it was asked for, plus one frame per this many
  /// features of its keyframes (the build takes about that long at the offline frame rate):
  /// small windows arrive early, big ones do not make tracking wait.
  int handoverFeaturesPerFrame = 3000;
  /// Keyframes farther than this beyond the window's edge (metres, measured on the ground plane
  /// as the window is) keep their float descriptors as 8-bit codes: a quarter of their memory.
  /// No pool of the place the camera is in reads them; a return there, relocalization and place
  /// recognition read them back as floats. Negative: never.
  double compactBeyond = 1.0;
  /// Keyframes nearer keep their float descriptors as half floats: half their memory, and a
  /// frame's ratio-test matches against them are those against the floats.
  bool halfFloatDescriptors = true;
  FeaturePoolOptions pool;

  /// Its INI keys (section [local_map]), listed once for loading and saving.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("window_size", o.windowSize);
    k("window_shift", o.windowShift);
    k("window_shift_angle", o.windowShiftAngle);
    k("pool_in_background", o.backgroundPreparation);
    k("pool_handover_frames", o.handoverFrames);
    k("pool_handover_features_per_frame", o.handoverFeaturesPerFrame);
    k("compact_beyond", o.compactBeyond);
    k("half_float_descriptors", o.halfFloatDescriptors);
    FeaturePoolOptions::forEachKey(o.pool, k);
  }

  /// Section [local_map]: the window's keys and its pool's. Unknown keys and bad values are
  /// errors naming them.
  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
};

/// What the pool preparation cost so far.
struct PoolPreparationStats {
  std::vector<double> windowMs;     ///< building each window's index
  std::vector<double> keyframeMs;   ///< building each new keyframe's own index
  std::vector<size_t> windowSizes;  ///< features in each window's index
  size_t windowsSkipped = 0;        ///< superseded before they were built (live only)
};

class LocalMap {
 public:
  LocalMap(const LocalMapOptions& options, std::shared_ptr<KeyframeGraph> graph);
  ~LocalMap();  ///< waits for the build in progress, if any
  LocalMap(const LocalMap&) = delete;
  LocalMap& operator=(const LocalMap&) = delete;

  /// Start of every frame: hands over the pools that are due (or ready, live). Returns the
  /// milliseconds spent waiting for one (always 0 live).
  double beginFrame();
  /// The pool this frame is matched against: the window's index plus the keyframes since.
  const FeaturePool& pool() const { return pool_; }

  /// A keyframe joined the graph: it enters the quadtree, and its features the pool from the
  /// next frame on.
  void keyframeAdded(KeyframeId id);
  /// Asks for the active window around `center`: after a keyframe, an optimization, a shift.
  void requestWindow(const Pose& center, const CameraIntrinsics& K);
  /// The camera is farther than T from the centre of the window asked for last.
  bool shiftNeeded(const Pose& camera) const;
  /// The window asked for last is not in the pool yet.
  bool windowPending() const;
  /// The keyframe's features are in the pool (or it had none to add).
  bool includes(KeyframeId id) const;

  PoolPreparationStats statistics() const;
  const LocalMapOptions& options() const { return options_; }

 private:
  struct Job;
  void syncQuadTree();
  void compactKeyframes(const Eigen::Vector2d& windowCentre);
  std::shared_ptr<Job> submit(PoolSnapshot snapshot, bool window, uint64_t due);
  void handOver(const Job& job);
  void rebuildPool();
  void workerLoop();

  LocalMapOptions options_;
  std::shared_ptr<KeyframeGraph> graph_;
  QuadTree quadTree_;
  std::map<KeyframeId, Eigen::Vector2d> indexedPositions_;
  /// How each keyframe keeps its descriptors, once compacted (binary ones are left as they are).
  std::map<KeyframeId, DescriptorStorage> compacted_;

  // Tracking thread only.
  FeaturePool pool_;
  std::shared_ptr<const PoolPart> windowPart_;
  KeyframeId windowNewest_ = 0;  ///< keyframes up to this id were in the window's snapshot
  bool haveWindow_ = false;
  std::vector<std::shared_ptr<const PoolPart>> keyframeParts_;  ///< spawned since the window
  std::vector<KeyframeId> keyframesHandedOver_;                 ///< their ids (parts may be empty)
  KeyframeId newestKeyframe_ = 0;
  bool haveKeyframe_ = false;
  Pose requestedCenter_ = Pose::Identity();
  uint64_t frame_ = 0;
  uint64_t nextSequence_ = 0, requestedWindow_ = 0, handedOverWindow_ = 0;

  // Shared with the worker.
  mutable std::mutex mutex_;
  std::condition_variable workAvailable_, workDone_;
  std::deque<std::shared_ptr<Job>> jobs_;  ///< submitted and not handed over, in order
  PoolPreparationStats stats_;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace slamdunk
