#pragma once
// Converts a TUM-layout RGB-D folder into an MRPT rawlog of CObservation3DRangeScan.

#include <slamdunk/core/TumSequence.h>

#include <functional>
#include <string>

namespace slamdunk {

struct TumToRawlogOptions {
  std::string sequenceFolder;
  std::string rawlogPath;
  std::string groundTruthPath;  ///< empty: "<rawlog without extension>_groundtruth.txt"
  RgbdCameraCalibration calibration;
  bool externalImages = false;           ///< images in "<name>_Images/" beside the rawlog
  bool groundTruthObservations = false;  ///< also a CObservationRobotPose per frame
  double maxDifference = 0.02;
  size_t maxFrames = 0;  ///< 0 = all
  /// Keep every stride-th associated frame (1 = all): the same motion at a lower frame rate,
  /// so stride times the motion between frames, as a faster hand would give.
  size_t stride = 1;
};

struct TumToRawlogSummary {
  size_t frames = 0;
  size_t rgbUnpaired = 0, depthUnpaired = 0;
  double firstStamp = 0, lastStamp = 0;
  size_t groundTruthPoses = 0;
  size_t groundTruthObservations = 0;
  std::string groundTruthPath;
  std::string imagesFolder;  ///< empty unless external images
};

/// Writes the rawlog (and images folder, ground truth) atomically: on any error nothing the user
/// already had at those paths is replaced. progress(done, total) is called after each frame.
TumToRawlogSummary convertTumToRawlog(const TumToRawlogOptions& opts,
                                      const std::function<void(size_t, size_t)>& progress = {});

}  // namespace slamdunk
