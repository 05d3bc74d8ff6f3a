#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>
#include <slamdunk/core/PngHeader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TextParsing.h>
#include <slamdunk/core/TimestampAssociation.h>
#include <slamdunk/core/TumSequence.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/system/datetime.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk {

RgbdCameraCalibration RgbdCameraCalibration::loadFromIni(const std::string& path) {
  if (!fs::is_regular_file(path))
    throw std::runtime_error("camera file '" + path + "' does not exist");
  try {
    // Inside the try: MRPT's parser itself throws on some malformed files (e.g. "${X}" naming
    // an undefined variable), and that error must name the file too.
    mrpt::config::CConfigFile cfg(path);
    return loadFromConfig(cfg);
  } catch (const std::exception& e) {
    throw std::runtime_error("camera file '" + path + "': " + summarizeError(e.what()));
  }
}

namespace {

CameraIntrinsics readIntrinsics(IniSectionReader& r) {
  CameraIntrinsics K;
  const auto res = r.readDoubles("resolution", {640, 480}, 2);
  // Checked before the conversion: a double beyond INT_MAX does not convert to an int.
  for (double v : res)
    if (!(v >= 1 && v <= 100000 && v == std::floor(v)))
      throw std::invalid_argument("[" + r.section() +
                                  "] resolution must be two whole numbers of pixels in "
                                  "[1, 100000]");
  K.width = static_cast<int>(res[0]);
  K.height = static_cast<int>(res[1]);
  K.fx = r.readDouble("fx", K.fx);
  K.fy = r.readDouble("fy", K.fy);
  K.cx = r.readDouble("cx", K.cx);
  K.cy = r.readDouble("cy", K.cy);
  const auto d = r.readDoubles("dist", {0, 0, 0, 0, 0}, 5);
  for (size_t i = 0; i < 5; ++i) K.dist[i] = d[i];
  return K;
}

void checkIntrinsics(const CameraIntrinsics& K, const std::string& section) {
  if (K.width <= 0 || K.height <= 0)
    throw std::invalid_argument("[" + section + "] resolution must be positive");
  if (!(K.fx > 0 && K.fy > 0))
    throw std::invalid_argument("[" + section + "] fx and fy must be positive");
  // Values no camera has (fx = 1e300, ...) would turn every projection into inf or NaN.
  if (const std::string bad = K.problem(); !bad.empty())
    throw std::invalid_argument("[" + section + "] " + bad);
}

// A rotation matrix given row by row. Calibration tools print R to six or more digits, so
// anything further than 1e-4 from a rotation is a wrong matrix (a scale, a reflection, a typo),
// not rounding; what is within is made exactly orthonormal.
Eigen::Matrix3d readRotation(IniSectionReader& r, const std::string& key) {
  const auto v = r.readDoubles(key, {1, 0, 0, 0, 1, 0, 0, 0, 1}, 9);
  const Eigen::Matrix3d R =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(v.data());
  const double offOrthonormal = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  if (!(offOrthonormal < 1e-4) || !(R.determinant() > 0))
    throw std::invalid_argument("[" + r.section() + "] " + key +
                                " is not a rotation matrix (R R^T differs from the identity by " +
                                std::to_string(offOrthonormal) + ", determinant " +
                                std::to_string(R.determinant()) + ")");
  return Eigen::Quaterniond(R).normalized().toRotationMatrix();
}

}  // namespace

std::string stampLatencyProblem(double ms) {
  constexpr double kMaxStampLatencyMs = 100;
  if (std::abs(ms) <= kMaxStampLatencyMs) return {};  // NaN fails this too
  return "must be within +-" + std::to_string(static_cast<int>(kMaxStampLatencyMs)) +
         " ms (found " + std::to_string(ms) + ")";
}

RgbdCameraCalibration RgbdCameraCalibration::loadFromConfig(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section) {
  IniSectionReader r(cfg, section);
  if (!r.sectionExists()) throw std::invalid_argument("no [" + section + "] section");
  RgbdCameraCalibration c;
  c.intrinsics = readIntrinsics(r);
  c.depthFactor = r.readDouble("depth_factor", c.depthFactor);
  c.stampLatencyMs = r.readDouble("stamp_latency_ms", c.stampLatencyMs);
  r.rejectUnknownKeys();
  checkIntrinsics(c.intrinsics, section);
  if (!(c.depthFactor > 0)) throw std::invalid_argument("depth_factor must be positive");
  if (const std::string bad = stampLatencyProblem(c.stampLatencyMs); !bad.empty())
    throw std::invalid_argument("[" + section + "] stamp_latency_ms " + bad);

  const std::string depthSection = section + "_DEPTH";
  IniSectionReader d(cfg, depthSection);
  if (d.sectionExists()) {
    c.depthCamera = readIntrinsics(d);
    const auto centre = d.readDoubles("colour_centre", {0, 0, 0}, 3);
    c.colourCentreInDepth = {centre[0], centre[1], centre[2]};
    c.depthToColourRotation = readRotation(d, "colour_rotation");
    d.rejectUnknownKeys();
    checkIntrinsics(*c.depthCamera, depthSection);
  }
  return c;
}

namespace {

struct ListEntry {
  double stamp;
  std::string file;
};

std::vector<ListEntry> readImageList(const fs::path& listPath) {
  std::ifstream in(listPath);
  if (!in) throw std::runtime_error("missing image list '" + listPath.string() + "'");
  std::vector<ListEntry> out;
  forEachDataLine(in, [&](const std::string& line, size_t lineNo) {
    std::istringstream fields(line);
    std::string stampText, file, extra;
    fields >> stampText >> file;
    const std::optional<double> stamp = parseNumber(stampText);
    if (file.empty() || !stamp || !std::isfinite(*stamp) || (fields >> extra))
      throw std::runtime_error(listPath.string() + ":" + std::to_string(lineNo) +
                               ": expected 'timestamp filename'");
    out.push_back({*stamp, file});
  });
  return out;
}

/// Throws when a PNG's header declares another size than the calibration's.
void checkDeclaredSize(const std::string& name, const std::string& path,
                       const CameraIntrinsics& K) {
  const auto size = pngFileSize(path);
  if (size && (size->width != uint32_t(K.width) || size->height != uint32_t(K.height)))
    throw std::runtime_error(name + " is " + std::to_string(size->width) + "x" +
                             std::to_string(size->height) + ", the camera calibration says " +
                             std::to_string(K.width) + "x" + std::to_string(K.height));
}

}  // namespace

TumSequence::TumSequence(const std::string& folder, double maxDifference) : folder_(folder) {
  const fs::path dir(folder);
  if (!fs::is_directory(dir))
    throw std::runtime_error("sequence folder '" + folder + "' not found");
  const auto rgb = readImageList(dir / "rgb.txt");
  const auto depth = readImageList(dir / "depth.txt");
  rgbCount_ = rgb.size();
  depthCount_ = depth.size();

  std::vector<double> rgbStamps, depthStamps;
  for (const auto& e : rgb) rgbStamps.push_back(e.stamp);
  for (const auto& e : depth) depthStamps.push_back(e.stamp);
  for (const auto& [i, j] : associateTimestamps(rgbStamps, depthStamps, maxDifference)) {
    TumFrameEntry f;
    f.rgbStamp = rgb[i].stamp;
    f.depthStamp = depth[j].stamp;
    f.rgbFile = (dir / rgb[i].file).string();
    f.depthFile = (dir / depth[j].file).string();
    frames_.push_back(f);
  }
  if (fs::exists(dir / "groundtruth.txt"))
    groundTruth_ = readTumTrajectory((dir / "groundtruth.txt").string());
}

mrpt::obs::CObservation3DRangeScan::Ptr TumSequence::loadObservation(
    size_t i, const RgbdCameraCalibration& calib) const {
  const TumFrameEntry& f = frames_.at(i);
  const auto& K = calib.intrinsics;
  // Image names come from the lists (an absolute name leaves the folder): messages name the
  // list too, and quote the name printably.
  const auto image = [&](const char* what, const std::string& file, const char* list) {
    return std::string(what) + " '" + printableText(file, 300) + "' (listed in '" +
           (fs::path(folder_) / list).string() + "')";
  };
  const std::string colourName = image("colour image", f.rgbFile, "rgb.txt");
  const std::string depthName = image("depth image", f.depthFile, "depth.txt");
  std::error_code ec;  // e.g. a name too long for the file system: missing all the same
  if (!fs::is_regular_file(f.rgbFile, ec)) throw std::runtime_error(colourName + " is missing");
  if (!fs::is_regular_file(f.depthFile, ec)) throw std::runtime_error(depthName + " is missing");

  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->sensorLabel = "RGBD";
  obs->timestamp = mrpt::Clock::fromDouble(calib.exposureTime(f.rgbStamp));

  // A PNG's declared size is checked before decoding: the decoder would allocate whatever a
  // corrupt header declares (up to gigabytes) before finding the data missing.
  const CameraIntrinsics& depthK = calib.depthCamera ? *calib.depthCamera : K;
  checkDeclaredSize(colourName, f.rgbFile, K);
  checkDeclaredSize(depthName, f.depthFile, depthK);

  if (!obs->intensityImage.loadFromFile(f.rgbFile))
    throw std::runtime_error("cannot decode " + colourName);
  const int w = static_cast<int>(obs->intensityImage.getWidth());
  const int h = static_cast<int>(obs->intensityImage.getHeight());
  if (w != K.width || h != K.height)
    throw std::runtime_error(colourName + " is " + std::to_string(w) + "x" + std::to_string(h) +
                             ", the camera calibration says " + std::to_string(K.width) + "x" +
                             std::to_string(K.height));
  obs->hasIntensityImage = true;

  cv::Mat depth = cv::imread(f.depthFile, cv::IMREAD_UNCHANGED);
  if (depth.empty()) throw std::runtime_error("cannot decode " + depthName);
  if (depth.type() != CV_16UC1)
    throw std::runtime_error(depthName + " is not a 16-bit single-channel PNG (found " +
                             std::to_string(depth.elemSize1() * 8) + "-bit, " +
                             std::to_string(depth.channels()) + " channel(s))");
  if (depth.cols != depthK.width || depth.rows != depthK.height)
    throw std::runtime_error(depthName + " is " + std::to_string(depth.cols) + "x" +
                             std::to_string(depth.rows) + ", expected " +
                             std::to_string(depthK.width) + "x" + std::to_string(depthK.height));
  if (calib.depthCamera)
    depth = registerDepthToColour(depth, depthK, K, calib.depthToColour(), 1.0 / calib.depthFactor);
  setDepthImage(*obs, depth, calib.depthFactor);

  obs->cameraParamsIntensity = K.toTCamera();
  obs->cameraParams = obs->cameraParamsIntensity;  // depth is registered to colour
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  return obs;
}

}  // namespace slamdunk
