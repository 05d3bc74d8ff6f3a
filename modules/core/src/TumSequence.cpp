#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/IniOptions.h>
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
  mrpt::config::CConfigFile cfg(path);
  try {
    return loadFromConfig(cfg);
  } catch (const std::exception& e) {
    throw std::runtime_error("camera file '" + path + "': " + e.what());
  }
}

namespace {

CameraIntrinsics readIntrinsics(IniSectionReader& r) {
  CameraIntrinsics K;
  const auto res = r.readDoubles("resolution", {640, 480}, 2);
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
}

}  // namespace

RgbdCameraCalibration RgbdCameraCalibration::loadFromConfig(
    const mrpt::config::CConfigFileBase& cfg, const std::string& section) {
  IniSectionReader r(cfg, section);
  if (!r.sectionExists()) throw std::invalid_argument("no [" + section + "] section");
  RgbdCameraCalibration c;
  c.intrinsics = readIntrinsics(r);
  c.depthFactor = r.readDouble("depth_factor", c.depthFactor);
  r.rejectUnknownKeys();
  checkIntrinsics(c.intrinsics, section);
  if (!(c.depthFactor > 0)) throw std::invalid_argument("depth_factor must be positive");

  const std::string depthSection = section + "_DEPTH";
  IniSectionReader d(cfg, depthSection);
  if (d.sectionExists()) {
    c.depthCamera = readIntrinsics(d);
    const auto centre = d.readDoubles("colour_centre", {0, 0, 0}, 3);
    c.colourCentreInDepth = {centre[0], centre[1], centre[2]};
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
  std::string line;
  size_t lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::string stampText, file, extra;
    fields >> stampText >> file;
    char* end = nullptr;
    const double stamp = std::strtod(stampText.c_str(), &end);
    if (file.empty() || *end != '\0' || !std::isfinite(stamp) || (fields >> extra))
      throw std::runtime_error(listPath.string() + ":" + std::to_string(lineNo) +
                               ": expected 'timestamp filename'");
    out.push_back({stamp, file});
  }
  return out;
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
  if (!fs::exists(f.rgbFile))
    throw std::runtime_error("colour image '" + f.rgbFile + "' is missing");
  if (!fs::exists(f.depthFile))
    throw std::runtime_error("depth image '" + f.depthFile + "' is missing");

  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->sensorLabel = "RGBD";
  obs->timestamp = mrpt::Clock::fromDouble(f.rgbStamp);

  if (!obs->intensityImage.loadFromFile(f.rgbFile))
    throw std::runtime_error("cannot decode colour image '" + f.rgbFile + "'");
  const int w = static_cast<int>(obs->intensityImage.getWidth());
  const int h = static_cast<int>(obs->intensityImage.getHeight());
  if (w != K.width || h != K.height)
    throw std::runtime_error("colour image '" + f.rgbFile + "' is " + std::to_string(w) + "x" +
                             std::to_string(h) + ", the camera calibration says " +
                             std::to_string(K.width) + "x" + std::to_string(K.height));
  obs->hasIntensityImage = true;

  cv::Mat depth = cv::imread(f.depthFile, cv::IMREAD_UNCHANGED);
  if (depth.empty()) throw std::runtime_error("cannot decode depth image '" + f.depthFile + "'");
  if (depth.type() != CV_16UC1)
    throw std::runtime_error("depth image '" + f.depthFile +
                             "' is not a 16-bit single-channel PNG (found " +
                             std::to_string(depth.elemSize1() * 8) + "-bit, " +
                             std::to_string(depth.channels()) + " channel(s))");
  const CameraIntrinsics& depthK = calib.depthCamera ? *calib.depthCamera : K;
  if (depth.cols != depthK.width || depth.rows != depthK.height)
    throw std::runtime_error("depth image '" + f.depthFile + "' is " + std::to_string(depth.cols) +
                             "x" + std::to_string(depth.rows) + ", expected " +
                             std::to_string(depthK.width) + "x" + std::to_string(depthK.height));
  if (calib.depthCamera)
    depth = registerDepthToColour(depth, depthK, K, calib.depthToColour(), 1.0 / calib.depthFactor);
  obs->hasRangeImage = true;
  obs->range_is_depth = true;
  obs->rangeImage_setSize(depth.rows, depth.cols);
  for (int r = 0; r < depth.rows; ++r) {
    const uint16_t* row = depth.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) obs->rangeImage(r, c) = row[c];
  }
  obs->rangeUnits = static_cast<float>(1.0 / calib.depthFactor);
  obs->maxRange = static_cast<float>(65535.0 / calib.depthFactor);

  obs->cameraParamsIntensity = K.toTCamera();
  obs->cameraParams = obs->cameraParamsIntensity;  // depth is registered to colour
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  return obs;
}

}  // namespace slamdunk
