#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/slam/SimpleMapExport.h>

#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <cmath>
#include <stdexcept>

namespace slamdunk {

Pose toMrptSensorWorld(const Pose& T_world_optical) {
  return opticalInSensor() * opticalToSensorPose(T_world_optical);
}

Pose fromMrptSensorWorld(const Pose& T_W_sensor) {
  return opticalInSensor().inverse() * sensorToOpticalPose(T_W_sensor);
}

namespace {
bool hasImages(const Keyframe& kf) { return !kf.depth.empty() && !kf.colour.empty(); }
}  // namespace

mrpt::obs::CObservation3DRangeScan::Ptr keyframeToObservation(const Keyframe& kf,
                                                              int points3DDecimation) {
  if (points3DDecimation < 0 || points3DDecimation > 255)
    throw std::invalid_argument("points3D decimation must be in [0, 255]");
  if (!hasImages(kf))
    throw std::invalid_argument("keyframe " + std::to_string(kf.id) + " kept no images");
  if (kf.depth.type() != CV_32F || kf.colour.size() != kf.depth.size())
    throw std::invalid_argument("keyframe " + std::to_string(kf.id) +
                                ": depth must be CV_32F and the size of the colour image");
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->sensorLabel = "SLAMDUNK_KEYFRAME";
  obs->timestamp = mrpt::Clock::fromDouble(kf.timestamp);
  obs->sensorPose = mrpt::poses::CPose3D();  // the simple map's pose is the camera's own pose

  obs->hasRangeImage = true;
  obs->range_is_depth = true;
  obs->rangeUnits = float(kSimpleMapDepthUnits);
  obs->rangeImage_setSize(kf.depth.rows, kf.depth.cols);
  for (int r = 0; r < kf.depth.rows; ++r) {
    const float* row = kf.depth.ptr<float>(r);
    for (int c = 0; c < kf.depth.cols; ++c) {
      const double units = std::round(double(row[c]) / kSimpleMapDepthUnits);
      // Invalid (0, NaN) and out-of-range (>= 6.5535 m) depths become 0 = "no data".
      obs->rangeImage(r, c) = (units > 0 && units < 65535.0) ? uint16_t(units) : uint16_t(0);
    }
  }

  obs->hasIntensityImage = true;
  obs->intensityImage = mrpt::img::CImage(kf.colour, mrpt::img::DEEP_COPY);
  obs->intensityImageChannel = mrpt::obs::CObservation3DRangeScan::CH_VISIBLE;
  // Depth is registered to colour: one camera model for both, and coincident cameras.
  obs->cameraParams = kf.intrinsics.toTCamera();
  obs->cameraParamsIntensity = obs->cameraParams;
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  if (points3DDecimation > 0) {
    mrpt::obs::T3DPointsProjectionParams pp;
    pp.decimation = uint8_t(points3DDecimation);
    obs->unprojectInto(*obs, pp);  // sensor-frame points, as MRPT's point maps expect
  }
  return obs;
}

mrpt::maps::CSimpleMap buildSimpleMap(const KeyframeGraph& graph, bool keyframesWithoutImages,
                                      int points3DDecimation) {
  mrpt::maps::CSimpleMap map;
  for (const auto& [id, pose] : graph.poses()) {
    const KeyframePtr kf = graph.keyframe(id);
    auto sf = mrpt::obs::CSensoryFrame::Create();
    if (hasImages(*kf))
      sf->insert(keyframeToObservation(*kf, points3DDecimation));
    else if (!keyframesWithoutImages)
      continue;
    // Zero covariance: the pose is the SLAM estimate itself; MRPT tools use the mean.
    auto pdf = mrpt::poses::CPose3DPDFGaussian::Create();
    pdf->mean = toCPose3D(toMrptSensorWorld(pose));
    map.insert(pdf, sf);
  }
  return map;
}

void exportSimpleMap(const KeyframeGraph& graph, const std::string& path, int points3DDecimation) {
  const mrpt::maps::CSimpleMap map = buildSimpleMap(graph, false, points3DDecimation);
  if (map.empty())
    throw std::runtime_error("cannot export '" + path + "': none of the " +
                             std::to_string(graph.keyframeCount()) +
                             " keyframes kept its images (set keep_keyframe_images = true in "
                             "the [tracker] section)");
  writeGzArchive(path, map);
}

}  // namespace slamdunk
