#pragma once
// SlamDunk behind MRPT's incremental map-builder interface (as CMetricMapBuilderICP/RBPF are),
// so MRPT-style applications can drive it with (action, sensory frame) pairs from a rawlog.
//
// Frame conventions:
//  - Input: every CObservation3DRangeScan of a sensory frame is one RGB-D frame (actions, e.g.
//    odometry, are ignored: SlamDunk is visual only). Other observation types are skipped.
//  - Output poses follow MRPT: the pose of the camera's *sensor* frame (x forward, y left,
//    z up) in a world that is the first camera's sensor frame (z up), optionally moved by the
//    x0 given to initialize(). See toMrptSensorWorld() in SimpleMapExport.h. The SLAM system
//    itself (system()) keeps the optical convention (world = first camera's optical frame).
//  - getCurrentlyBuiltMetricMap(): a CMultiMetricMap holding one CKeyframeGraphMap that shares
//    the SLAM system's graph (its getVisualizationInto() shows the map z-up in the same world,
//    without the x0 offset).

#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SlamOptions.h>
#include <slamdunk/slam/SlamSystem.h>

#include <mrpt/poses/CPose3D.h>
#include <mrpt/slam/CMetricMapBuilder.h>

#include <memory>
#include <mutex>

namespace slamdunk {

class CSlamDunkMapBuilder : public mrpt::slam::CMetricMapBuilder {
 public:
  explicit CSlamDunkMapBuilder(const SlamOptions& options = SlamOptions());
  ~CSlamDunkMapBuilder() override;

  /// Starts a new map. Only an empty initialMap is supported (SlamDunk cannot resume from a
  /// CSimpleMap: std::invalid_argument otherwise); x0 (its mean) places the first camera in
  /// the output world.
  void initialize(const mrpt::maps::CSimpleMap& initialMap = mrpt::maps::CSimpleMap(),
                  const mrpt::poses::CPosePDF* x0 = nullptr) override;

  /// Latest tracked camera pose (the last good one while lost), MRPT sensor convention, as a
  /// CPose3DPDFGaussian with zero covariance (SlamDunk does not estimate one).
  mrpt::poses::CPose3DPDF::Ptr getCurrentPoseEstimation() const override;

  /// Feeds every CObservation3DRangeScan of the sensory frame to the SLAM system.
  void processActionObservation(mrpt::obs::CActionCollection& action,
                                mrpt::obs::CSensoryFrame& observations) override;

  /// One entry per keyframe (increasing id): its pose and, when the keyframe kept its images
  /// (tracker keep_keyframe_images), the observation rebuilt from them; else an empty frame.
  void getCurrentlyBuiltMap(mrpt::maps::CSimpleMap& out_map) const override;
  /// Number of keyframes.
  unsigned int getCurrentlyBuiltMapSize() override;
  const mrpt::maps::CMultiMetricMap* getCurrentlyBuiltMetricMap() const override;
  /// Not supported (SlamDunk's map is 3D): logs a warning and writes nothing.
  void saveCurrentEstimationToImage(const std::string& file, bool formatEMF_BMP = true) override;

  /// Waits for pending optimizations (and runs the final global pass if enabled).
  void finish();

  const SlamSystem& system() const { return *system_; }
  /// The keyframe map sharing the SLAM system's graph (the one in the metric map).
  const std::shared_ptr<CKeyframeGraphMap>& keyframeGraphMap() const { return keyframeMap_; }
  /// Result of the last processed frame (status Lost with no pose before the first frame).
  TrackingResult lastResult() const;
  size_t framesProcessed() const;

 private:
  void reset();

  SlamOptions options_;
  std::unique_ptr<SlamSystem> system_;
  std::shared_ptr<CKeyframeGraphMap> keyframeMap_;
  mrpt::maps::CMultiMetricMap metricMap_;
  mrpt::poses::CPose3D worldOffset_;  ///< x0 of initialize()
  TrackingResult last_;
  bool anyTracked_ = false;
  mutable std::mutex mutex_;  // processing vs. the const getters (e.g. from a GUI thread)
};

}  // namespace slamdunk
