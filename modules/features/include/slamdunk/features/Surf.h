#pragma once
// SURF: Speeded-Up Robust Features (Bay, Ess, Tuytelaars, Van Gool, CVIU 2008), written from the
// paper because the system's OpenCV ships without the non-free xfeatures2d module.

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <string>
#include <vector>

namespace slamdunk {

/// Settings of slamdunk::Surf (also reachable as Surf::Params).
struct SurfParams {
  /// Keep maxima whose Hessian determinant exceeds this. Each lobe of the box filters is
  /// averaged (sum / lobe area) on a 0..255 image, as in OpenCV's SURF, so values tuned there
  /// carry over. On 7-Scenes VGA frames 500 gives ~400-600 keypoints, 100 about 1600.
  double hessianThreshold = 500.0;
  /// Number of octaves; each doubles the filter-size step and the sampling step.
  int nOctaves = 4;
  /// Scales searched per octave; each octave evaluates nOctaveLayers + 2 filter sizes.
  int nOctaveLayers = 2;
  /// false: 64-value descriptor; true: 128 values (sums split by the sign of the other axis).
  bool extended = false;
  /// true: skip orientation assignment (faster; fine when the camera does not roll much).
  bool upright = false;
  /// Maxima are interpolated by fitting a quadratic in x, y and scale (Brown & Lowe); a maximum
  /// whose fitted offset exceeds this (in samples) in any axis is dropped. 0.5 (the paper's
  /// choice) keeps only well-centred maxima; 1.0 (OpenCV's) keeps ~20% more keypoints and, at
  /// equal keypoint count, was ~10 points more repeatable under a 30 degree rotation.
  double maxInterpolationOffset = 0.5;
  /// If > 0, keep only the strongest maxKeypoints detections before computing orientations and
  /// descriptors (saves time; the same as truncating the sorted output).
  int maxKeypoints = 0;
};

/// SURF keypoint detector (Fast-Hessian) and descriptor, usable anywhere a cv::Feature2D is.
///
/// Output conventions (the same as OpenCV's SURF, so code written for it carries over):
/// - KeyPoint::pt: pixel centres at integer coordinates.
/// - KeyPoint::size: box-filter size in pixels (9 at the finest scale); the paper's scale is
///   s = 1.2 / 9 * size and the descriptor window is 20 s wide.
/// - KeyPoint::response: Hessian determinant at the (interpolated) maximum, in the units of
///   Params::hessianThreshold.
/// - KeyPoint::angle: dominant orientation in degrees [0, 360) in image coordinates (y down), or
///   -1 in upright mode.
/// - KeyPoint::octave: octave index (0 = finest). KeyPoint::class_id: sign of the Laplacian (trace
///   of the Hessian), +1 for dark blobs on bright background, -1 for bright blobs; only keypoints
///   with equal sign can match, which halves matching work.
/// - Detected keypoints are sorted by response, strongest first (ties broken by position), so a
///   caller can keep the best N by truncating.
/// - Descriptors: CV_32F rows of 64 (or 128 if extended) values with unit L2 norm.
///
/// Output is deterministic, also when computed on several threads (cv::parallel_for_). Calls
/// from different threads are safe; each calling thread keeps its scratch memory (about 7 MB
/// for a VGA image) between calls, which saves ~1400 page faults per frame.
class Surf : public cv::Feature2D {
 public:
  using Params = SurfParams;

  explicit Surf(const Params& params = Params());
  static cv::Ptr<Surf> create(const Params& params = Params());

  /// image: 8-bit or 16-bit, 1, 3 (BGR) or 4 (BGRA) channels; colour is converted to grey and
  /// 16-bit values are scaled by 1/257 to 0..255. Other depths/channel counts throw cv::Exception.
  /// mask: empty or CV_8UC1 of the image size; keypoints are kept where it is non-zero.
  /// With useProvidedKeypoints, orientations (unless upright) and descriptors are computed for the
  /// given keypoints (size = filter size, must be > 0); keypoints outside the image are removed.
  void detectAndCompute(cv::InputArray image, cv::InputArray mask,
                        std::vector<cv::KeyPoint>& keypoints, cv::OutputArray descriptors,
                        bool useProvidedKeypoints = false) override;

  int descriptorSize() const override { return params_.extended ? 128 : 64; }
  int descriptorType() const override { return CV_32F; }
  int defaultNorm() const override { return cv::NORM_L2; }
  cv::String getDefaultName() const override { return "slamdunk.Surf"; }
  bool empty() const override { return false; }

  /// Describes the given keypoints with every descriptor window turned by angleDegrees (image
  /// coordinates, y down), whatever Params::upright says: a rolled view described as the view
  /// it is rolled against would describe it. Keypoints outside the image are removed.
  void computeTurned(cv::InputArray image, std::vector<cv::KeyPoint>& keypoints,
                     cv::OutputArray descriptors, float angleDegrees);
  /// The keypoint angle computeTurned() gives its keypoints for a turn: in [0, 360).
  static float turnedAngle(float angleDegrees);

  const Params& params() const { return params_; }

 private:
  Params params_;
};

}  // namespace slamdunk
