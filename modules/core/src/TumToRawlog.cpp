#include <slamdunk/core/TumToRawlog.h>

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/TimestampAssociation.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {

std::string defaultGroundTruthPath(const std::string& rawlogPath) {
  fs::path p(rawlogPath);
  return (p.parent_path() / (p.stem().string() + "_groundtruth.txt")).string();
}

}  // namespace

TumToRawlogSummary convertTumToRawlog(const TumToRawlogOptions& opts,
                                      const std::function<void(size_t, size_t)>& progress) {
  if (opts.stride < 1) throw std::invalid_argument("stride must be at least 1");
  const TumSequence seq(opts.sequenceFolder, opts.maxDifference);
  const std::string groundTruthPath =
      opts.groundTruthPath.empty() ? defaultGroundTruthPath(opts.rawlogPath) : opts.groundTruthPath;
  // `--gt` pointed at the source's groundtruth.txt would turn the user's ground truth into
  // this tool's copy.
  const fs::path dir(opts.sequenceFolder);
  rejectPathClashes({{"ground truth", (dir / "groundtruth.txt").string()},
                     {"colour list", (dir / "rgb.txt").string()},
                     {"depth list", (dir / "depth.txt").string()}},
                    {{"rawlog", opts.rawlogPath},
                     {"ground-truth output", seq.hasGroundTruth() ? groundTruthPath : ""}});
  if (seq.frames().empty())
    throw std::runtime_error("no colour/depth pair in '" + opts.sequenceFolder +
                             "' associates within " + std::to_string(opts.maxDifference) + " s");

  TumToRawlogSummary sum;
  // The associated frames converted, in order: every stride-th, at most maxFrames of them.
  std::vector<size_t> kept;
  for (size_t i = 0; i < seq.frames().size(); i += opts.stride) kept.push_back(i);
  if (opts.maxFrames && kept.size() > opts.maxFrames) kept.resize(opts.maxFrames);
  const size_t n = kept.size();
  sum.rgbUnpaired = seq.rgbCount() - seq.frames().size();
  sum.depthUnpaired = seq.depthCount() - seq.frames().size();
  const RgbdCameraCalibration& calib = opts.calibration;
  sum.firstStamp = calib.exposureTime(seq.frames().front().rgbStamp);
  sum.lastStamp = calib.exposureTime(seq.frames()[kept.back()].rgbStamp);

  // Ground-truth pose per frame (nearest stamp, TUM association) for the optional observations.
  std::vector<int> gtIndexOfFrame(n, -1);
  if (opts.groundTruthObservations && seq.hasGroundTruth()) {
    std::vector<double> frameStamps, gtStamps;
    for (size_t i = 0; i < n; ++i)
      frameStamps.push_back(calib.exposureTime(seq.frames()[kept[i]].rgbStamp));
    for (const auto& p : seq.groundTruth()) gtStamps.push_back(p.timestamp);
    for (const auto& [i, j] : associateTimestamps(frameStamps, gtStamps, opts.maxDifference))
      gtIndexOfFrame[i] = static_cast<int>(j);
  }

  AtomicOutput rawlogOut(opts.rawlogPath);
  std::unique_ptr<AtomicOutputFolder> images;
  if (opts.externalImages) {
    sum.imagesFolder = RawlogReader::imagesDirectoryFor(opts.rawlogPath);
    images = std::make_unique<AtomicOutputFolder>(sum.imagesFolder);
  }
  {
    mrpt::io::CFileGZOutputStream file;
    if (!file.open(rawlogOut.tempPath()))
      throw std::runtime_error("cannot write rawlog '" + opts.rawlogPath + "'");
    auto archive = mrpt::serialization::archiveFrom(file);
    for (size_t i = 0; i < n; ++i) {
      auto obs = seq.loadObservation(kept[i], opts.calibration);
      if (images) {
        char frameName[64];
        // The colour file is copied byte for byte (no re-encoding); depth goes to MRPT's own
        // external matrix format, which keeps the raw 16-bit values.
        const fs::path rgbSrc(seq.frames()[kept[i]].rgbFile);
        std::snprintf(frameName, sizeof(frameName), "%06zu_rgb", i);
        const std::string rgbName = frameName + rgbSrc.extension().string();
        fs::copy_file(rgbSrc, fs::path(images->tempPath()) / rgbName);
        obs->intensityImage.setExternalStorage(rgbName);
        std::snprintf(frameName, sizeof(frameName), "%06zu_depth.bin", i);
        obs->rangeImage_convertToExternalStorage(frameName, images->tempPath() + "/");
      }
      archive << *obs;
      if (gtIndexOfFrame[i] >= 0) {
        const Pose& T_w_opt = seq.groundTruth()[gtIndexOfFrame[i]].pose;
        mrpt::obs::CObservationRobotPose gt;
        gt.sensorLabel = "GROUND_TRUTH";
        gt.timestamp = obs->timestamp;
        gt.pose.mean = toCPose3D(opticalToSensorPose(T_w_opt));
        archive << gt;
        ++sum.groundTruthObservations;
      }
      ++sum.frames;
      if (progress) progress(i + 1, n);
    }
    file.close();
  }

  // Ground truth goes first: if it fails, the rawlog has not been replaced yet.
  if (seq.hasGroundTruth()) {
    sum.groundTruthPath = groundTruthPath;
    writeTumTrajectory(sum.groundTruthPath, seq.groundTruth(),
                       "ground truth of " + opts.sequenceFolder + " (optical frame, TUM format)");
    sum.groundTruthPoses = seq.groundTruth().size();
  }
  if (images) images->commit();
  rawlogOut.commit();
  return sum;
}

}  // namespace slamdunk
