#pragma once
// A TUM RGB-D benchmark folder (rgb.txt, depth.txt, optional groundtruth.txt) turned into
// CObservation3DRangeScan frames, colour and depth associated the TUM way.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/TumTrajectory.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace mrpt::config {
class CConfigFileBase;
}

namespace slamdunk {

/// Colour camera calibration plus the depth scale of the PNGs (raw units per metre), and the
/// depth camera when the depth images are not registered to colour.
struct RgbdCameraCalibration {
  CameraIntrinsics intrinsics;
  double depthFactor = 5000.0;
  /// Set when depth comes from a camera of its own: loadObservation registers it to colour.
  std::optional<CameraIntrinsics> depthCamera;
  /// The colour camera's centre in the depth camera's optical frame, metres.
  Eigen::Vector3d colourCentreInDepth = Eigen::Vector3d::Zero();
  /// Turns a direction in the depth camera's optical frame into the colour camera's (a stereo
  /// calibration's R); the identity when the two cameras' axes are parallel.
  Eigen::Matrix3d depthToColourRotation = Eigen::Matrix3d::Identity();
  /// Milliseconds from the middle of the colour image's exposure to its stamp in the source.
  /// The pipeline takes a frame's stamp as that middle (its rolling-shutter rows are timed
  /// around it); a driver that stamps a frame when it has arrived stamps it later, by half the
  /// readout and the transfer.
  double stampLatencyMs = 0;

  /// The instant a source stamp stands for: the middle of the colour exposure.
  double exposureTime(double sourceStamp) const { return sourceStamp - stampLatencyMs / 1000.0; }

  /// Depth camera frame -> colour camera frame (metres): p_colour = R (p_depth - centre).
  Eigen::Isometry3d depthToColour() const {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.linear() = depthToColourRotation;
    t.translation() = -(depthToColourRotation * colourCentreInDepth);
    return t;
  }

  /// Reads section [CAMERA] (the colour camera): resolution = [w h], fx, fy, cx, cy,
  /// dist = [k1 k2 p1 p2 k3], depth_factor, stamp_latency_ms (default 0); and the optional section
  /// [CAMERA_DEPTH] (a depth camera whose images are not registered to colour): resolution, fx, fy,
  /// cx, cy, dist, colour_centre = [x y z], colour_rotation = [R row by row] (default the
  /// identity). Unknown keys and malformed values are errors naming the key.
  static RgbdCameraCalibration loadFromIni(const std::string& path);
  static RgbdCameraCalibration loadFromConfig(const mrpt::config::CConfigFileBase& cfg,
                                              const std::string& section = "CAMERA");
};

/// Empty when `ms` is a plausible stamp latency (a driver's stamp after the middle of the
/// exposure); otherwise why not: more than 100 ms (three frames at 30 Hz) is a wrong clock or
/// unit, not a latency.
std::string stampLatencyProblem(double ms);

struct TumFrameEntry {
  double rgbStamp = 0, depthStamp = 0;
  std::string rgbFile, depthFile;  ///< absolute paths
};

class TumSequence {
 public:
  /// Parses the lists and associates them (|dt| < maxDifference). Throws std::runtime_error
  /// naming the file (and line) when a list is missing or malformed.
  explicit TumSequence(const std::string& folder, double maxDifference = 0.02);

  const std::string& folder() const { return folder_; }
  const std::vector<TumFrameEntry>& frames() const { return frames_; }
  size_t rgbCount() const { return rgbCount_; }
  size_t depthCount() const { return depthCount_; }
  bool hasGroundTruth() const { return !groundTruth_.empty(); }
  /// Empty when the folder has no groundtruth.txt.
  const Trajectory& groundTruth() const { return groundTruth_; }

  /// Loads frame i as an observation (timestamp = colour stamp, raw 16-bit depth copied with
  /// rangeUnits = 1/depthFactor, registered to colour first when the calibration has a depth
  /// camera: the observation is always a registered one). Throws naming the image on a missing or
  /// unreadable file, a depth PNG that is not 16-bit single channel, or a size that differs from
  /// the calibration.
  mrpt::obs::CObservation3DRangeScan::Ptr loadObservation(size_t i,
                                                          const RgbdCameraCalibration& calib) const;

 private:
  std::string folder_;
  std::vector<TumFrameEntry> frames_;
  size_t rgbCount_ = 0, depthCount_ = 0;
  Trajectory groundTruth_;
};

}  // namespace slamdunk
