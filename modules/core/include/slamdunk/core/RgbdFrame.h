#pragma once
// One RGB-D frame as the SLAM pipeline sees it: grey image, metric depth and the colour intrinsics.

#include <slamdunk/core/CameraIntrinsics.h>

#include <Eigen/Core>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>

namespace mrpt::obs {
class CObservation3DRangeScan;
}

namespace slamdunk {

/// Depth (CV_32F, 0 = none) at a sub-pixel position of `depth`, interpolated between the four
/// pixels around it when they all lie on one smooth surface (within 2 % of each other); 0
/// otherwise (a hole, an edge between surfaces, the image's last row or column, outside it).
double depthOnOneSurface(const cv::Mat& depth, double u, double v);

/// Depth (CV_32F metres, 0 = none) at a sub-pixel position of `depth`: interpolated between
/// the four pixels around it when they all lie on one smooth surface (within 2 % of each
/// other), else the nearest pixel's; 0 outside the image.
float interpolatedDepth(const cv::Mat& depth, double u, double v);

/// Loads everything `obs` keeps in external files, on the calling thread. MRPT's load() reads
/// the depth only: a lazily stored colour image is decoded on its first access instead, on
/// whichever thread that is (the tracking thread, where a file read can wait on the disk).
/// Readers and grabbers call this so the decoding stays theirs. Throws like MRPT when a file
/// is missing or unreadable.
void loadExternalImages(const mrpt::obs::CObservation3DRangeScan& obs);

/// Gives `obs` a 16-bit depth image (CV_16UC1, `depthFactor` units per metre as in TUM's
/// PNGs) as its range image: depth along the optical axis, its units and the range they reach.
void setDepthImage(mrpt::obs::CObservation3DRangeScan& obs, const cv::Mat& depth,
                   double depthFactor);

/// A deep copy of `obs` that holds its images itself: loaded (see loadExternalImages) and no
/// longer pointing into an images folder, whose names are relative to the source's rawlog and
/// mean nothing beside a copy written elsewhere (a recording, an edited rawlog). The copy shares
/// no pixel buffer with `obs`, which another thread may go on reading.
std::shared_ptr<mrpt::obs::CObservation3DRangeScan> selfContainedCopy(
    const mrpt::obs::CObservation3DRangeScan& obs);

class RgbdFrame {
 public:
  /// Builds a frame from an MRPT observation (loads externally stored images if needed).
  /// Throws std::runtime_error naming the problem: no intensity image, no depth, size mismatch.
  static RgbdFrame fromObservation(const mrpt::obs::CObservation3DRangeScan& obs);

  RgbdFrame() = default;
  RgbdFrame(double timestamp, cv::Mat grey, cv::Mat depthMetres, CameraIntrinsics intrinsics,
            cv::Mat colour = {});

  double timestamp() const { return timestamp_; }
  /// 8-bit single channel, colour camera resolution.
  const cv::Mat& grey() const { return grey_; }
  /// BGR colour image when the source had one (shares the observation's pixels), else empty.
  const cv::Mat& colour() const { return colour_; }
  /// CV_32F metres, registered to the colour image; 0 marks an invalid pixel.
  const cv::Mat& depth() const { return depth_; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

  /// Depth in metres at the nearest pixel, 0 when outside the image or invalid.
  float depthAt(double u, double v) const;
  /// Depth in metres at a sub-pixel position: interpolated between the four pixels around it
  /// when they all lie on one smooth surface (within 2 % of each other), else the nearest
  /// pixel's. A keypoint is located to a fraction of a pixel; on a slanted wall 2 m away the
  /// nearest pixel's depth alone is off by up to 3 mm.
  float interpolatedDepthAt(double u, double v) const;
  /// 3D point in the optical frame for a raw (distorted) pixel: undistorts the pixel, takes the
  /// (interpolated) depth at the raw pixel. Empty when the depth is invalid.
  std::optional<Eigen::Vector3d> backProject(double u, double v) const;
  /// Fraction of pixels with valid depth.
  double validDepthFraction() const;

 private:
  double timestamp_ = 0;
  cv::Mat grey_;
  cv::Mat colour_;
  cv::Mat depth_;
  CameraIntrinsics intrinsics_;
};

}  // namespace slamdunk
