#include <slamdunk/synthetic/SyntheticSequence.h>

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/synthetic/SyntheticRenderer.h>
#include <slamdunk/synthetic/SyntheticScene.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {

/// Seeded by (seed, frame): the noise of a frame does not depend on which frames were rendered
/// before it.
uint64_t frameSeed(unsigned seed, size_t frame) {
  return (uint64_t(seed) << 32) ^ (uint64_t(frame) * 0x9E3779B97F4A7C15ULL) ^ 0x5DEECE66DULL;
}

}  // namespace

cv::Mat kinectDepth(const cv::Mat& exact, double fx, uint64_t seed) {
  // A structured-light camera measures disparity d = f b / z against its projector: depth
  // noise grows with z² and comes in steps of a disparity quantum. Parameters of a Kinect v1
  // (Khoshelham & Elberink 2012; the simulation follows Handa et al., ICL-NUIM, 2014).
  constexpr double kBaseline = 0.075;          // m, projector to IR camera
  constexpr double kDisparityQuantum = 0.125;  // px: 1/8-pixel sub-pixel disparity
  constexpr double kDisparitySigma = 0.07;     // px: σ_z = z² σ_d / (f b) ≈ 1.8 mm at 1 m
  constexpr double kJitterSigma = 0.5;         // px: where the pattern lands, not exactly here
  const double fb = fx * kBaseline;
  cv::RNG rng(seed);
  cv::Mat out(exact.size(), CV_32F, cv::Scalar(0));
  for (int v = 0; v < exact.rows; ++v) {
    for (int u = 0; u < exact.cols; ++u) {
      const double su = u + rng.gaussian(kJitterSigma), sv = v + rng.gaussian(kJitterSigma);
      const int u0 = static_cast<int>(std::floor(su)), v0 = static_cast<int>(std::floor(sv));
      const double noise = rng.gaussian(kDisparitySigma);
      if (u0 < 0 || v0 < 0 || u0 + 1 >= exact.cols || v0 + 1 >= exact.rows) continue;
      const float z00 = exact.at<float>(v0, u0), z01 = exact.at<float>(v0, u0 + 1);
      const float z10 = exact.at<float>(v0 + 1, u0), z11 = exact.at<float>(v0 + 1, u0 + 1);
      if (!(z00 > 0 && z01 > 0 && z10 > 0 && z11 > 0)) continue;  // no pattern seen: a hole
      const double a = su - u0, b = sv - v0;
      const double z = (1 - b) * ((1 - a) * z00 + a * z01) + b * ((1 - a) * z10 + a * z11);
      const double d = std::round((fb / z + noise) / kDisparityQuantum) * kDisparityQuantum;
      if (d > 0) out.at<float>(v, u) = static_cast<float>(fb / d);
    }
  }
  return out;
}

CameraIntrinsics SyntheticOptions::intrinsics() const {
  CameraIntrinsics K;
  K.width = width;
  K.height = height;
  K.fx = fx;
  K.fy = fy;
  K.cx = cx;
  K.cy = cy;
  return K;
}

CameraIntrinsics SyntheticOptions::statedIntrinsics() const {
  CameraIntrinsics K = intrinsics();
  K.fx *= 1 + statedFocalErrorPercent / 100;
  K.fy *= 1 + statedFocalErrorPercent / 100;
  return K;
}

void SyntheticOptions::validate() const {
  if (!SyntheticTrajectory::isKnown(trajectory)) {
    std::string known;
    for (const auto& name : SyntheticTrajectory::names())
      known += (known.empty() ? "" : ", ") + name;
    throw std::invalid_argument("unknown trajectory '" + trajectory + "' (known: " + known + ")");
  }
  if (frames < 0 || frames == 1)
    throw std::invalid_argument("frames must be 0 (trajectory default) or at least 2, not " +
                                std::to_string(frames));
  if (jpegQuality < 0 || jpegQuality > 100)
    throw std::invalid_argument("JPEG quality must be 0 (colour as PNG) or in [1, 100], not " +
                                std::to_string(jpegQuality));
  if (jpegQuality > 0 && !externalImages)
    throw std::invalid_argument(
        "a JPEG quality needs external images (the rawlog embeds colour "
        "as MRPT serializes it)");
  if (firstFrames < 0 || firstFrames == 1)
    throw std::invalid_argument("first frames must be 0 (all) or at least 2, not " +
                                std::to_string(firstFrames));
  if (twinRooms && SyntheticTrajectory::sceneOf(trajectory) != "office")
    throw std::invalid_argument("twin rooms are the office's: trajectory 'tour' only, not '" +
                                trajectory + "'");
  if (bareCorridor && SyntheticTrajectory::sceneOf(trajectory) != "office")
    throw std::invalid_argument("the bare corridor is the office's: trajectory 'tour' only, not '" +
                                trajectory + "'");
  if (skipFrames < 0)
    throw std::invalid_argument("skipped frames must be 0 or more, not " +
                                std::to_string(skipFrames));
  if (width < 16 || height < 16 || width > 4096 || height > 4096)
    throw std::invalid_argument("image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is out of range (16..4096)");
  for (double v : {fx, fy})
    if (!(v > 0) || !std::isfinite(v))
      throw std::invalid_argument("focal lengths must be positive and finite");
  if (!std::isfinite(cx) || !std::isfinite(cy))
    throw std::invalid_argument("principal point must be finite");
  if (!(depthNoiseSigma >= 0) || depthNoiseSigma > 1.0)
    throw std::invalid_argument("depth noise sigma must be in [0, 1] m, not " +
                                std::to_string(depthNoiseSigma));
  auto inRange = [](double v, double lo, double hi, const char* what) {
    if (!(v >= lo && v <= hi))
      throw std::invalid_argument(std::string(what) + " must be in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "] ms, not " + std::to_string(v));
  };
  inRange(exposureMs, 0, 100, "exposure time");
  inRange(rollingShutterMs, 0, 100, "rolling-shutter readout time");
  inRange(depthTimeOffsetMs, -100, 100, "depth time offset");
  if (!(std::abs(statedFocalErrorPercent) <= 20))
    throw std::invalid_argument("stated focal length error must be in [-20, 20] %, not " +
                                std::to_string(statedFocalErrorPercent));
  if (motionSamples < 0 || motionSamples > 200)
    throw std::invalid_argument("motion samples must be in [0, 200], not " +
                                std::to_string(motionSamples));
  if (supersampling < 1 || supersampling % 2 == 0 || supersampling > 7)
    throw std::invalid_argument("supersampling must be 1, 3, 5 or 7");
}

void SyntheticOptions::enableHandHeldEffects() {
  exposureMs = 10;
  rollingShutterMs = 20;
  autoExposure = true;
  depthTimeOffsetMs = 5;
}

SyntheticSequence::SyntheticSequence(const SyntheticOptions& options) : options_(options) {
  options_.validate();
  groundTruth_ = SyntheticTrajectory::generate(options_.trajectory, options_.frames);
  if (size_t(options_.skipFrames) + 2 > groundTruth_.size())
    throw std::invalid_argument("skipping " + std::to_string(options_.skipFrames) + " of the " +
                                std::to_string(groundTruth_.size()) +
                                " frames of the path leaves fewer than 2");
  groundTruth_.erase(groundTruth_.begin(), groundTruth_.begin() + options_.skipFrames);
  if (options_.firstFrames > 0 && size_t(options_.firstFrames) < groundTruth_.size())
    groundTruth_.resize(size_t(options_.firstFrames));
  poseAt_ = SyntheticTrajectory::shape(options_.trajectory, options_.frames);
  const std::string scene = SyntheticTrajectory::sceneOf(options_.trajectory);
  FloorPlan plan = options_.twinRooms ? FloorPlan::officeWithTwinRooms() : FloorPlan::named(scene);
  if (options_.bareCorridor)
    plan = FloorPlan::withBareArea(std::move(plan), "corridor B-C",
                                   SyntheticOptions::kBareCorridorDetail);
  scene_ = std::make_unique<SyntheticScene>(std::move(plan), options_.seed, options_.ceiling);
  renderer_ = std::make_unique<SyntheticRenderer>(options_.intrinsics(), options_.supersampling);
}

SyntheticSequence::~SyntheticSequence() = default;

double SyntheticSequence::exposureGain(size_t i) const {
  if (!options_.autoExposure) return 1.0;
  // Two incommensurate drifts, phased by the seed: the gain wanders between about 0.6 and 1.5
  // within seconds, as a camera's auto exposure does when the view turns from a bright wall to
  // a dark corner.
  const double t = double(i) / SyntheticTrajectory::kFrameRate;
  const double p = 1.7 * options_.seed;
  return std::exp(0.3 * std::sin(2 * M_PI * t / 5.3 + p) +
                  0.15 * std::sin(2 * M_PI * t / 1.9 + 2.3 * p));
}

double SyntheticSequence::imageMotion(double fromFrame, double toFrame) const {
  // Points 2 m in front of the camera at the image corners and centre: the largest distance
  // one of them moves in the image.
  const CameraIntrinsics K = options_.intrinsics();
  const Pose from = poseAt_(fromFrame), to = poseAt_(toFrame);
  const Pose toFromFrom = to.inverse() * from;
  double largest = 0;
  for (const auto& [u, v] : {std::pair{0.0, 0.0},
                             {K.width - 1.0, 0.0},
                             {0.0, K.height - 1.0},
                             {K.width - 1.0, K.height - 1.0},
                             {K.cx, K.cy}}) {
    const Eigen::Vector3d q = toFromFrom * K.backProject(u, v, 2.0);
    if (q.z() <= 0) return 1e3;
    largest = std::max(largest, (K.project(q) - Eigen::Vector2d(u, v)).norm());
  }
  return largest;
}

cv::Mat SyntheticSequence::renderMotion(size_t i) {
  // In frames: the exposure of one row, and the readout from the top row to the bottom one.
  const double framesPerMs = SyntheticTrajectory::kFrameRate / 1000.0;
  const double exposure = options_.exposureMs * framesPerMs;
  const double readout = options_.rollingShutterMs * framesPerMs;
  // Renders spread evenly over every row's exposure, each standing for a slice of time of
  // length `slice`: by default as many as keep the image motion between two renders under
  // 1.5 px (a few while the hand holds still, about 17 at 90 deg/s in VGA).
  const double span = exposure + readout;
  const int renders =
      options_.motionSamples > 0
          ? options_.motionSamples
          : std::clamp(static_cast<int>(std::ceil(imageMotion(i - span / 2, i + span / 2) / 1.5)),
                       2, 48);
  const double slice = span / renders;
  // Row r is exposed over [t_r - w/2, t_r + w/2], t_r spread over the readout around frame i.
  const double window = std::max(exposure, slice);
  const int rows = options_.height;
  std::vector<double> rowTime(rows);
  for (int r = 0; r < rows; ++r) rowTime[r] = i + ((r + 0.5) / rows - 0.5) * readout;

  cv::Mat sum(rows, options_.width, CV_32FC3, cv::Scalar::all(0));
  std::vector<double> rowWeight(rows, 0.0);
  cv::Mat bgr, bgrF;
  for (int j = 0; j < renders; ++j) {
    const double t = i - span / 2 + (j + 0.5) * slice;
    // Each row takes the render by the time the two slices share.
    bool used = false;
    std::vector<double> weight(rows, 0.0);
    for (int r = 0; r < rows; ++r) {
      const double overlap = std::min(t + slice / 2, rowTime[r] + window / 2) -
                             std::max(t - slice / 2, rowTime[r] - window / 2);
      if (overlap > 0) weight[r] = overlap, used = true;
    }
    if (!used) continue;
    renderer_->renderColour(scene_->scene(), poseAt_(t), bgr);
    bgr.convertTo(bgrF, CV_32FC3);
    for (int r = 0; r < rows; ++r) {
      if (weight[r] <= 0) continue;
      cv::Mat row = sum.row(r);
      cv::scaleAdd(bgrF.row(r), weight[r], row, row);
      rowWeight[r] += weight[r];
    }
  }
  for (int r = 0; r < rows; ++r)
    if (rowWeight[r] > 0) sum.row(r) /= rowWeight[r];
  return sum;
}

void SyntheticSequence::renderRaw(size_t i, cv::Mat& bgr, cv::Mat& depthRaw,
                                  cv::Mat* kinectTwinDepthRaw) {
  if (i >= size())
    throw std::out_of_range("synthetic frame " + std::to_string(i) + " of " +
                            std::to_string(size()));
  const size_t p = i + size_t(options_.skipFrames);  // on the whole path
  const double depthFrame =
      p + options_.depthTimeOffsetMs * SyntheticTrajectory::kFrameRate / 1000.0;
  const bool separateDepth = options_.motionEffects() || options_.depthTimeOffsetMs != 0;
  cv::Mat colour, depth;
  renderer_->render(scene_->scene(), separateDepth ? poseAt_(depthFrame) : groundTruth_[i].pose,
                    colour, depth);
  if (options_.motionEffects())
    colour = renderMotion(p);
  else if (separateDepth)
    renderer_->renderColour(scene_->scene(), groundTruth_[i].pose, colour);
  // Gain, then 8 bits (saturating at white).
  colour.convertTo(bgr, CV_8UC3, exposureGain(p));
  if (kinectTwinDepthRaw) {
    if (options_.kinectDepth)
      throw std::logic_error("synthetic sequence: a Kinect twin of Kinect depth was asked for");
    *kinectTwinDepthRaw = measuredDepth(p, depth, true);
  }
  depthRaw = measuredDepth(p, depth, options_.kinectDepth);
}

cv::Mat SyntheticSequence::measuredDepth(size_t i, const cv::Mat& exactDepth, bool kinect) const {
  cv::Mat depth = kinect ? kinectDepth(exactDepth, options_.fx, frameSeed(options_.seed, i) + 1)
                         : exactDepth.clone();
  if (options_.depthNoiseSigma > 0) {
    cv::RNG rng(frameSeed(options_.seed, i));
    cv::Mat noise(depth.size(), CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.depthNoiseSigma);
    const cv::Mat valid = depth > 0;
    cv::Mat noisy = depth + noise;
    noisy.copyTo(depth, valid);
    depth.setTo(0, depth < 0);
  }
  // TUM raw units (0.2 mm), rounded to nearest; 0 = no surface. Depth is below the far clip
  // (12 m = 60000 units), so it always fits in 16 bits.
  cv::Mat raw;
  depth.convertTo(raw, CV_16U, kDepthFactor);
  return raw;
}

void SyntheticSequence::renderImages(size_t i, cv::Mat& bgr, cv::Mat& depthMetres) {
  cv::Mat raw;
  renderRaw(i, bgr, raw);
  raw.convertTo(depthMetres, CV_32F, 1.0 / kDepthFactor);
}

mrpt::obs::CObservation3DRangeScan::Ptr SyntheticSequence::renderFrame(
    size_t i, mrpt::obs::CObservation3DRangeScan::Ptr* kinectTwin) {
  cv::Mat bgr, raw, twinRaw;
  renderRaw(i, bgr, raw, kinectTwin ? &twinRaw : nullptr);
  if (kinectTwin) *kinectTwin = observation(i, bgr, twinRaw);
  return observation(i, bgr, raw);
}

mrpt::obs::CObservation3DRangeScan::Ptr SyntheticSequence::observation(size_t i, const cv::Mat& bgr,
                                                                       const cv::Mat& raw) const {
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->sensorLabel = kSensorLabel;
  obs->timestamp = mrpt::Clock::fromDouble(groundTruth_[i].timestamp);
  obs->hasIntensityImage = true;
  obs->intensityImage = mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
  setDepthImage(*obs, raw, kDepthFactor);
  obs->cameraParamsIntensity = options_.statedIntrinsics().toTCamera();
  obs->cameraParams = obs->cameraParamsIntensity;  // depth is registered to colour
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  obs->sensorPose = mrpt::poses::CPose3D();  // the world pose lives in the ground-truth file
  return obs;
}

std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> renderSyntheticSequence(
    const SyntheticOptions& options, Trajectory* groundTruthOut, const ProgressCallback& progress) {
  SyntheticSequence seq(options);
  std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> out;
  out.reserve(seq.size());
  for (size_t i = 0; i < seq.size(); ++i) {
    out.push_back(seq.renderFrame(i));
    if (progress) progress(i + 1, seq.size());
  }
  if (groundTruthOut) *groundTruthOut = seq.groundTruth();
  return out;
}

std::string defaultSyntheticGroundTruthPath(const std::string& rawlogPath) {
  const fs::path p(rawlogPath);
  const std::string stem = p.extension() == ".rawlog" ? p.stem().string() : p.filename().string();
  return (p.parent_path() / (stem + "_groundtruth.txt")).string();
}

namespace {

/// One output rawlog, and its images folder with external images; replaced only by commit().
class SyntheticRawlogWriter {
 public:
  /// jpegQuality: with external images, colour as JPEG of that quality; 0 = PNG.
  SyntheticRawlogWriter(const std::string& rawlogPath, bool externalImages, int jpegQuality)
      : out_(rawlogPath), jpegQuality_(jpegQuality) {
    if (externalImages) {
      imagesFolder_ = RawlogReader::imagesDirectoryFor(rawlogPath);
      images_ = std::make_unique<AtomicOutputFolder>(imagesFolder_);
    }
    if (!file_.open(out_.tempPath()))
      throw std::runtime_error("cannot write rawlog '" + rawlogPath + "'");
  }

  const std::string& imagesFolder() const { return imagesFolder_; }

  /// Appends frame i. With external images, a colour image another writer already made of the
  /// same image (colourFile) is hard-linked (copied where the folder cannot link), not encoded
  /// again: a Kinect twin's colour takes no second copy on disk. Returns this writer's colour
  /// file.
  std::string write(mrpt::obs::CObservation3DRangeScan& obs, size_t i,
                    const std::string& colourFile = {}) {
    std::string rgbFile;
    if (images_) {
      // Same layout as tum2rawlog: colour as PNG (lossless) or JPEG, depth as MRPT's external
      // matrix (raw 16-bit values), names relative to the images folder.
      char name[64];
      std::snprintf(name, sizeof(name), "%06zu_rgb.%s", i, jpegQuality_ > 0 ? "jpg" : "png");
      rgbFile = (fs::path(images_->tempPath()) / name).string();
      if (colourFile.empty()) {
        std::vector<int> params;
        if (jpegQuality_ > 0) params = {cv::IMWRITE_JPEG_QUALITY, jpegQuality_};
        if (!cv::imwrite(rgbFile, obs.intensityImage.asCvMatRef(), params))
          throw std::runtime_error("cannot write image '" + rgbFile + "'");
      } else {
        std::error_code linkError;
        fs::create_hard_link(colourFile, rgbFile, linkError);
        if (linkError) fs::copy_file(colourFile, rgbFile);
      }
      obs.intensityImage.setExternalStorage(name);
      std::snprintf(name, sizeof(name), "%06zu_depth.bin", i);
      obs.rangeImage_convertToExternalStorage(name, images_->tempPath() + "/");
    }
    auto archive = mrpt::serialization::archiveFrom(file_);
    archive << obs;
    return rgbFile;
  }

  void close() { file_.close(); }
  void commit() {
    if (images_) images_->commit();
    out_.commit();
  }

 private:
  AtomicOutput out_;
  int jpegQuality_;
  std::unique_ptr<AtomicOutputFolder> images_;
  std::string imagesFolder_;
  mrpt::io::CFileGZOutputStream file_;
};

}  // namespace

SyntheticSequenceSummary writeSyntheticSequence(const SyntheticOptions& options,
                                                const std::string& rawlogPath,
                                                const std::string& groundTruthPath,
                                                const ProgressCallback& progress,
                                                const std::string& kinectTwinRawlogPath) {
  if (rawlogPath.empty()) throw std::invalid_argument("no output rawlog path given");
  const bool twin = !kinectTwinRawlogPath.empty();
  if (twin && options.kinectDepth)
    throw std::invalid_argument(
        "a Kinect-depth twin needs a sequence of its own depth (drop --kinect-depth)");
  SyntheticSequenceSummary sum;
  sum.rawlogPath = rawlogPath;
  sum.groundTruthPath =
      groundTruthPath.empty() ? defaultSyntheticGroundTruthPath(rawlogPath) : groundTruthPath;
  std::vector<NamedPath> outputs{{"the rawlog", rawlogPath},
                                 {"the ground truth", sum.groundTruthPath}};
  if (twin) {
    sum.kinectTwinRawlogPath = kinectTwinRawlogPath;
    sum.kinectTwinGroundTruthPath = defaultSyntheticGroundTruthPath(kinectTwinRawlogPath);
    outputs.push_back({"the Kinect twin's rawlog", kinectTwinRawlogPath});
    outputs.push_back({"the Kinect twin's ground truth", sum.kinectTwinGroundTruthPath});
    if (options.externalImages) {
      outputs.push_back({"the images folder", RawlogReader::imagesDirectoryFor(rawlogPath)});
      outputs.push_back({"the Kinect twin's images folder",
                         RawlogReader::imagesDirectoryFor(kinectTwinRawlogPath)});
    }
  }
  // Compared as files, not as text ("./a.rawlog" and "a.rawlog" are one file).
  rejectPathClashes({}, outputs);

  SyntheticSequence seq(options);  // validates before any file is touched
  sum.frames = seq.size();
  sum.scene = seq.scene().plan().name;
  sum.stats = SyntheticTrajectory::stats(seq.groundTruth());

  SyntheticRawlogWriter writer(rawlogPath, options.externalImages, options.jpegQuality);
  std::unique_ptr<SyntheticRawlogWriter> twinWriter;
  if (twin)
    twinWriter = std::make_unique<SyntheticRawlogWriter>(
        kinectTwinRawlogPath, options.externalImages, options.jpegQuality);
  sum.imagesFolder = writer.imagesFolder();
  for (size_t i = 0; i < seq.size(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    mrpt::obs::CObservation3DRangeScan::Ptr twinObs;
    auto obs = seq.renderFrame(i, twin ? &twinObs : nullptr);
    sum.renderSeconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string colourPng = writer.write(*obs, i);
    if (twinWriter) twinWriter->write(*twinObs, i, colourPng);
    if (progress) progress(i + 1, seq.size());
  }
  writer.close();
  if (twinWriter) twinWriter->close();
  // Ground truth first: if it fails, neither the rawlog nor the images have been replaced.
  const std::string comment = "synthetic RGB-D ground truth: trajectory '" + options.trajectory +
                              "', seed " + std::to_string(options.seed) +
                              " (optical frame T_w_opt, world y down, floor at y = " +
                              std::to_string(seq.scene().plan().floorY) + ")";
  writeTumTrajectory(sum.groundTruthPath, seq.groundTruth(), comment);
  if (twinWriter) writeTumTrajectory(sum.kinectTwinGroundTruthPath, seq.groundTruth(), comment);
  writer.commit();
  if (twinWriter) twinWriter->commit();
  return sum;
}

}  // namespace slamdunk
