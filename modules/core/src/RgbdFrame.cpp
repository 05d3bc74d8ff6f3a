#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/ExternalDepthFile.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/core/RgbdFrame.h>

#include <algorithm>
#include <cmath>

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/poses/CPose3D.h>

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/system/datetime.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace slamdunk {

namespace {
std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

/// The intrinsics must describe the image they come with: fx, cx, ... of a 640x480 calibration
/// applied to a 320x240 image put every point in the wrong place (garbage poses, not an error).
/// A resolution left unset (0x0) by a driver is taken from the image.
void matchResolution(CameraIntrinsics& K, const cv::Mat& image, const std::string& what,
                     const char* field) {
  if (K.width == image.cols && K.height == image.rows) return;
  if (K.width == 0 && K.height == 0) {
    K.width = image.cols;
    K.height = image.rows;
    return;
  }
  throw std::runtime_error(what + " is " + sizeText(image.cols, image.rows) +
                           " but its intrinsics (" + field + ") are for " +
                           sizeText(K.width, K.height));
}
}  // namespace

void loadExternalImages(const mrpt::obs::CObservation3DRangeScan& obs) {
  loadExternalDepthFile(obs);  // load() skips a depth image already loaded
  obs.load();
  // forceLoad() leaves an image that is not externally stored as it is.
  if (obs.hasIntensityImage) obs.intensityImage.forceLoad();
  if (obs.hasConfidenceImage) obs.confidenceImage.forceLoad();
}

void setDepthImage(mrpt::obs::CObservation3DRangeScan& obs, const cv::Mat& depth,
                   double depthFactor) {
  CV_Assert(depth.type() == CV_16UC1);
  obs.hasRangeImage = true;
  obs.range_is_depth = true;
  obs.rangeImage_setSize(depth.rows, depth.cols);
  for (int r = 0; r < depth.rows; ++r) {
    const uint16_t* row = depth.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) obs.rangeImage(r, c) = row[c];
  }
  obs.rangeUnits = static_cast<float>(1.0 / depthFactor);
  obs.maxRange = static_cast<float>(65535.0 / depthFactor);
}

std::shared_ptr<mrpt::obs::CObservation3DRangeScan> selfContainedCopy(
    const mrpt::obs::CObservation3DRangeScan& obs) {
  loadExternalImages(obs);
  auto copy = std::make_shared<mrpt::obs::CObservation3DRangeScan>(obs);
  // CImage copies share their pixels, and an externally stored one keeps its file name.
  if (obs.hasIntensityImage)
    copy->intensityImage =
        mrpt::img::CImage(obs.intensityImage.asCvMatRef().clone(), mrpt::img::SHALLOW_COPY);
  if (obs.hasConfidenceImage)
    copy->confidenceImage =
        mrpt::img::CImage(obs.confidenceImage.asCvMatRef().clone(), mrpt::img::SHALLOW_COPY);
  copy->rangeImage_forceResetExternalStorage();
  return copy;
}

RgbdFrame::RgbdFrame(double timestamp, cv::Mat grey, cv::Mat depthMetres,
                     CameraIntrinsics intrinsics, cv::Mat colour)
    : timestamp_(timestamp),
      grey_(std::move(grey)),
      colour_(std::move(colour)),
      depth_(std::move(depthMetres)),
      intrinsics_(intrinsics) {
  if (grey_.type() != CV_8UC1) throw std::invalid_argument("RgbdFrame: grey image must be CV_8UC1");
  if (depth_.type() != CV_32FC1)
    throw std::invalid_argument("RgbdFrame: depth image must be CV_32FC1 (metres)");
  if (grey_.size() != depth_.size())
    throw std::invalid_argument("RgbdFrame: colour image is " + std::to_string(grey_.cols) + "x" +
                                std::to_string(grey_.rows) + " but depth is " +
                                std::to_string(depth_.cols) + "x" + std::to_string(depth_.rows));
}

RgbdFrame RgbdFrame::fromObservation(const mrpt::obs::CObservation3DRangeScan& obs) {
  const std::string what = "observation '" + printableText(obs.sensorLabel) +
                           "' at t=" + std::to_string(mrpt::Clock::toDouble(obs.timestamp));
  loadExternalImages(obs);
  if (!obs.hasIntensityImage || obs.intensityImage.isEmpty())
    throw std::runtime_error(what + " has no colour (intensity) image");
  if (!obs.hasRangeImage || obs.rangeImage.rows() == 0)
    throw std::runtime_error(what + " has no depth (range) image");
  if (!obs.range_is_depth)
    throw std::runtime_error(what + " stores ranges along rays, not depth: not supported");
  // The largest raw value must stay a finite depth: 65535 * 3e38 would be inf metres.
  if (!(obs.rangeUnits > 0) || !std::isfinite(obs.rangeUnits * 65535.0f))
    throw std::runtime_error(what + " has invalid rangeUnits " + std::to_string(obs.rangeUnits) +
                             " (must be positive, 65535 units a finite depth)");

  const cv::Mat& colour = obs.intensityImage.asCvMatRef();
  cv::Mat grey;
  if (colour.channels() == 3)
    cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
  else if (colour.channels() == 4)
    cv::cvtColor(colour, grey, cv::COLOR_BGRA2GRAY);
  else
    grey = colour.clone();
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);

  CameraIntrinsics K = CameraIntrinsics::fromTCamera(obs.cameraParamsIntensity);
  matchResolution(K, grey, what + ": colour image", "cameraParamsIntensity");
  if (const std::string bad = K.problem(); !bad.empty())
    throw std::runtime_error(what + " has invalid colour camera intrinsics: " + bad);

  const auto& range = obs.rangeImage;
  cv::Mat depth(static_cast<int>(range.rows()), static_cast<int>(range.cols()), CV_32F);
  const float units = obs.rangeUnits;
  for (int r = 0; r < depth.rows; ++r) {
    float* row = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c) row[c] = static_cast<float>(range(r, c)) * units;
  }
  if (!obs.doDepthAndIntensityCamerasCoincide()) {
    // MRPT's convention: the images are pixel-aligned only when the two cameras coincide;
    // otherwise (a raw Kinect, say) depth is registered to colour here.
    CameraIntrinsics depthK = CameraIntrinsics::fromTCamera(obs.cameraParams);
    matchResolution(depthK, depth, what + ": depth image", "cameraParams");
    if (const std::string bad = depthK.problem(); !bad.empty())
      throw std::runtime_error(what + " has invalid depth camera intrinsics: " + bad);
    if (!isValidPose(fromCPose3D(obs.relativePoseIntensityWRTDepth)))
      throw std::runtime_error(what +
                               ": relativePoseIntensityWRTDepth is not a rigid transform (NaN, "
                               "inf or a rotation that is not orthonormal)");
    const mrpt::poses::CPose3D opticalInSensor(0, 0, 0, mrpt::DEG2RAD(-90.0), 0,
                                               mrpt::DEG2RAD(-90.0));
    // Depth optical frame -> depth sensor frame -> colour optical frame.
    const mrpt::poses::CPose3D depthToColour = opticalInSensor - obs.relativePoseIntensityWRTDepth;
    Eigen::Isometry3d T;
    T.matrix() = depthToColour.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>().asEigen();
    depth = registerDepthToColour(depth, depthK, K, T);
  } else if (depth.cols != grey.cols || depth.rows != grey.rows) {
    throw std::runtime_error(what + ": depth is " + std::to_string(depth.cols) + "x" +
                             std::to_string(depth.rows) + " but colour is " +
                             std::to_string(grey.cols) + "x" + std::to_string(grey.rows) +
                             " and relativePoseIntensityWRTDepth says the cameras coincide");
  }
  return RgbdFrame(mrpt::Clock::toDouble(obs.timestamp), std::move(grey), std::move(depth), K,
                   colour.channels() == 3 ? colour : cv::Mat());
}

namespace {
float nearestDepth(const cv::Mat& depth, double u, double v) {
  const int c = static_cast<int>(std::lround(u)), r = static_cast<int>(std::lround(v));
  if (c < 0 || r < 0 || c >= depth.cols || r >= depth.rows) return 0.f;
  const float z = depth.at<float>(r, c);
  return std::isfinite(z) && z > 0 ? z : 0.f;
}
}  // namespace

double depthOnOneSurface(const cv::Mat& depth, double u, double v) {
  if (!(std::abs(u) < 1e8 && std::abs(v) < 1e8)) return 0;  // also NaN
  const double fu = std::floor(u), fv = std::floor(v);
  const int c = static_cast<int>(fu), r = static_cast<int>(fv);
  if (c < 0 || r < 0 || c + 1 >= depth.cols || r + 1 >= depth.rows) return 0;
  const float z00 = depth.at<float>(r, c), z01 = depth.at<float>(r, c + 1);
  const float z10 = depth.at<float>(r + 1, c), z11 = depth.at<float>(r + 1, c + 1);
  const float lo = std::min({z00, z01, z10, z11}), hi = std::max({z00, z01, z10, z11});
  if (!(lo > 0) || !std::isfinite(hi) || hi - lo > 0.02f * lo) return 0;
  const double a = u - fu, b = v - fv;
  return (1 - b) * ((1 - a) * z00 + a * z01) + b * ((1 - a) * z10 + a * z11);
}

float interpolatedDepth(const cv::Mat& depth, double u, double v) {
  const double z = depthOnOneSurface(depth, u, v);
  return z > 0 ? static_cast<float>(z) : nearestDepth(depth, u, v);
}

float RgbdFrame::depthAt(double u, double v) const { return nearestDepth(depth_, u, v); }

float RgbdFrame::interpolatedDepthAt(double u, double v) const {
  return interpolatedDepth(depth_, u, v);
}

std::optional<Eigen::Vector3d> RgbdFrame::backProject(double u, double v) const {
  const float z = interpolatedDepthAt(u, v);
  if (z <= 0) return std::nullopt;
  const Eigen::Vector2d und = intrinsics_.undistortPixel(u, v);
  return intrinsics_.backProject(und.x(), und.y(), z);
}

double RgbdFrame::validDepthFraction() const {
  if (depth_.empty()) return 0;
  return static_cast<double>(cv::countNonZero(depth_ > 0)) / depth_.total();
}

}  // namespace slamdunk
