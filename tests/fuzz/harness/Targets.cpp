#include "Targets.h"

#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/core/TumSequence.h>
#include <slamdunk/core/TumToRawlog.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/live/LiveOptions.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SlamOptions.h>
#include <slamdunk/slam/SlamSystem.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <opencv2/imgcodecs.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk::fuzz {

// ------------------------------------------------------------------ files

Bytes readFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read '" + path + "'");
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeFileBytes(const std::string& path, const Bytes& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
}

/// A "Vm...:" figure of /proc/self/status (given in KiB) in MiB; 0 when absent.
long procStatusMiB(const std::string& key) {
  std::ifstream s("/proc/self/status");
  std::string line;
  while (std::getline(s, line))
    if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1)) / 1024;
  return 0;
}

long peakRssMiB() { return procStatusMiB("VmHWM"); }
long currentVmSizeMiB() { return procStatusMiB("VmSize"); }

void resetPeakRss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
}

Bytes inflateFile(const std::string& path) {
  mrpt::io::CFileGZInputStream in;
  if (!in.open(path)) throw std::runtime_error("cannot open '" + path + "'");
  Bytes out;
  uint8_t buf[1 << 16];
  for (;;) {
    const size_t n = in.Read(buf, sizeof buf);
    if (n == 0) break;
    out.insert(out.end(), buf, buf + n);
  }
  return out;
}

namespace {

void writeGz(const std::string& path, const Bytes& data) {
  mrpt::io::CFileGZOutputStream out;
  if (!out.open(path)) throw std::runtime_error("cannot write '" + path + "'");
  out.Write(data.data(), data.size());
}

void writeText(const std::string& path, const std::string& text) {
  writeFileBytes(path, Bytes(text.begin(), text.end()));
}

Bytes serialize(const std::vector<const mrpt::serialization::CSerializable*>& objects) {
  mrpt::io::CMemoryStream mem;
  auto out = mrpt::serialization::archiveFrom(mem);
  for (const auto* o : objects) out << *o;
  const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
  return Bytes(p, p + mem.getTotalBytesCount());
}

/// Thrown when data a reader accepted makes a later stage (what the apps do next) throw where
/// the apps would not expect it: the driver counts it as a failure, not a rejection.
struct UseFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ------------------------------------------------------------------ seed frames

/// A small textured RGB-D frame: blocks of random grey levels (features to find) in front of a
/// slanted plane 1-2 m away. Deterministic for a seed.
mrpt::obs::CObservation3DRangeScan::Ptr makeObservation(int w, int h, uint64_t seed, double t) {
  Rng rng(seed);
  cv::Mat colour(h, w, CV_8UC3);
  const int block = std::max(2, w / 10);
  for (int by = 0; by < h; by += block)
    for (int bx = 0; bx < w; bx += block) {
      const cv::Vec3b c(uint8_t(rng.next()), uint8_t(rng.next()), uint8_t(rng.next()));
      colour(cv::Rect(bx, by, std::min(block, w - bx), std::min(block, h - by))).setTo(c);
    }
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->sensorLabel = "RGBD";
  obs->timestamp = mrpt::Clock::fromDouble(1000.0 + t);
  obs->intensityImage = mrpt::img::CImage(colour, mrpt::img::DEEP_COPY);
  obs->hasIntensityImage = true;
  obs->hasRangeImage = true;
  obs->range_is_depth = true;
  obs->rangeUnits = 0.001f;
  obs->rangeImage_setSize(h, w);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) obs->rangeImage(r, c) = uint16_t(1000 + 10 * c + 5 * r);
  obs->rangeImage(0, 0) = 0;  // one invalid pixel, as sensors have
  mrpt::img::TCamera cam;
  cam.ncols = uint32_t(w);
  cam.nrows = uint32_t(h);
  cam.setIntrinsicParamsFromValues(0.82 * w, 0.82 * w, 0.5 * (w - 1), 0.5 * (h - 1));
  obs->cameraParamsIntensity = cam;
  obs->cameraParams = cam;
  return obs;
}

/// A ground-truth pose observation as tum2rawlog --gt-observations writes (fixed timestamp:
/// MRPT's default is the current time, which would make the corpus differ on every run).
mrpt::obs::CObservationRobotPose::Ptr poseObservation() {
  auto p = mrpt::obs::CObservationRobotPose::Create();
  p->sensorLabel = "GROUND_TRUTH";
  p->timestamp = mrpt::Clock::fromDouble(1000.0);
  return p;
}

/// Frames the map target feeds to a pipeline started from the loaded map (as --load-map).
const std::vector<mrpt::obs::CObservation3DRangeScan::Ptr>& mapProbeFrames() {
  static const std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames = [] {
    std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> v;
    for (int k = 0; k < 2; ++k) v.push_back(makeObservation(80, 60, 7 + k, 0.1 * k));
    return v;
  }();
  return frames;
}

SlamOptions fuzzSlamOptions() {
  SlamOptions o;
  o.optimizerThread = false;  // inline: deterministic, no thread per input
  return o;
}

/// A value that is usually plausible and sometimes hostile (NaN, inf, 0, negative, extreme).
double hostile(Rng& rng, double plausible, unsigned percent = 15) {
  return rng.chance(percent) ? interestingDouble(rng) : plausible;
}

// ------------------------------------------------------------------ rawlog

/// Observations with valid framing but inconsistent content: image sizes that disagree with
/// each other and with the intrinsics, zero/NaN/inf intrinsics and rangeUnits (depth in metres
/// overflowing to inf), cameras that do not coincide, missing images, odd pixel formats.
Bytes generateRawlog(Rng& rng) {
  std::vector<mrpt::serialization::CSerializable::Ptr> keep;
  std::vector<const mrpt::serialization::CSerializable*> objects;
  const int frames = 1 + int(rng.below(3));
  for (int k = 0; k < frames; ++k) {
    const bool sizeChange = rng.chance(30);
    const int w = sizeChange ? 1 + int(rng.below(64)) : 40;
    const int h = sizeChange ? 1 + int(rng.below(48)) : 30;
    auto obs = makeObservation(w, h, rng.next(), 0.033 * k);
    if (rng.chance(15)) {  // odd colour formats: grey, 4 channels, 16-bit
      static const int types[] = {CV_8UC1, CV_8UC4, CV_16UC1, CV_16UC3};
      cv::Mat m(h, w, types[rng.below(4)], cv::Scalar::all(double(rng.below(256))));
      obs->intensityImage = mrpt::img::CImage(m, mrpt::img::DEEP_COPY);
    }
    if (rng.chance(20)) {  // depth of another size than colour
      const int dh = 1 + int(rng.below(48)), dw = 1 + int(rng.below(64));
      obs->rangeImage_setSize(dh, dw);
      for (int r = 0; r < dh; ++r)
        for (int c = 0; c < dw; ++c) obs->rangeImage(r, c) = uint16_t(rng.next());
    }
    if (rng.chance(15)) obs->rangeUnits = float(hostile(rng, 3e38, 60));
    auto hostileCamera = [&](mrpt::img::TCamera& cam) {
      if (rng.chance(20)) cam.ncols = uint32_t(rng.chance(50) ? 0 : rng.next());
      if (rng.chance(20)) cam.nrows = uint32_t(rng.chance(50) ? 0 : rng.next());
      cam.setIntrinsicParamsFromValues(hostile(rng, cam.fx()), hostile(rng, cam.fy()),
                                       hostile(rng, cam.cx()), hostile(rng, cam.cy()));
      for (size_t d = 0; d < 5; ++d) cam.dist[d] = hostile(rng, 0.0, 5);
    };
    if (rng.chance(50)) hostileCamera(obs->cameraParamsIntensity);
    if (rng.chance(40)) {
      // Cameras that do not coincide: depth is registered to colour (maybe with a bad pose).
      const mrpt::poses::CPose3D coincide(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
      obs->relativePoseIntensityWRTDepth =
          coincide + mrpt::poses::CPose3D(hostile(rng, 0.025), hostile(rng, 0.0, 5), 0, 0, 0, 0);
      hostileCamera(obs->cameraParams);
    }
    if (rng.chance(5)) obs->hasIntensityImage = false;
    if (rng.chance(5)) obs->hasRangeImage = false;
    if (rng.chance(5)) obs->range_is_depth = false;
    if (rng.chance(5)) obs->timestamp = INVALID_TIMESTAMP;
    if (rng.chance(20)) {
      // The action / sensory-frame rawlog format.
      auto acts = mrpt::obs::CActionCollection::Create();
      auto sf = mrpt::obs::CSensoryFrame::Create();
      sf->insert(obs);
      if (rng.chance(50)) sf->insert(poseObservation());
      keep.push_back(acts);
      keep.push_back(sf);
    } else {
      keep.push_back(obs);
    }
    if (rng.chance(10)) keep.push_back(poseObservation());
  }
  for (const auto& o : keep) objects.push_back(o.get());
  return serialize(objects);
}

extern "C" void __sanitizer_set_report_path(const char* path) __attribute__((weak));

/// Memory MRPT may take for one input of the corpus' size (a few KB) before the input counts as
/// one it cannot read safely: far above any real need, far below the seconds that zero-filling
/// gigabytes takes on a loaded machine.
constexpr long kMrptPrecheckMiB = 256;

/// MRPT 2.5.8's deserializers trust the sizes they read: a corrupt range-image size overflows
/// rows * cols and writes past the buffer (CObservation3DRangeScan::serializeFrom ->
/// rangeImage_setSize), and a corrupt string or vector length is allocated and zero-filled
/// (up to 4 GiB for a string, more for the point vectors) before the data turns out missing.
/// Both happen inside MRPT's ReadObject, before the project sees the object. This reads the
/// file with MRPT alone in a child process to tell those inputs apart.
std::string rawlogMrptPrecheck(const Bytes& in, const RunContext& ctx) {
  const std::string path = ctx.dir + "/precheck.rawlog";
  writeFileBytes(path, in);
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork() failed");
  if (pid == 0) {
    // A sanitizer report here is MRPT's, not the project's: keep it out of the run's logs.
    if (__sanitizer_set_report_path)
      __sanitizer_set_report_path((ctx.dir + "/mrpt-report").c_str());
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGALRM}) signal(sig, SIG_DFL);
    alarm(20);
#if !defined(__SANITIZE_ADDRESS__)
    // Without AddressSanitizer (which reserves terabytes of address space, and whose own
    // allocation cap main.cpp sets), cap the address space so that a huge allocation fails at
    // once instead of being zero-filled.
    if (const long vm = currentVmSizeMiB(); vm > 0) {
      const rlimit lim{rlim_t(vm + kMrptPrecheckMiB) << 20, rlim_t(vm + kMrptPrecheckMiB) << 20};
      setrlimit(RLIMIT_AS, &lim);
    }
#endif
    resetPeakRss();
    const long baseMiB = peakRssMiB();  // what the driver itself holds
    int code = 0;
    try {
      mrpt::io::CFileGZInputStream f(path);
      auto a = mrpt::serialization::archiveFrom(f);
      for (;;) (void)a.ReadObject();
    } catch (const std::bad_alloc&) {
      code = 10;
    } catch (const std::exception& e) {
      const std::string msg = e.what();
      if (msg.find("bad_alloc") != std::string::npos ||
          msg.find("Failed to allocate") != std::string::npos ||
          msg.find("Insufficient memory") != std::string::npos)
        code = 10;
    }
    if (peakRssMiB() - baseMiB > kMrptPrecheckMiB) code = 10;
    _exit(code);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  fs::remove(path);
  if (WIFSIGNALED(status))
    return std::string("MRPT's deserializer itself ") +
           (WTERMSIG(status) == SIGALRM ? "hangs"
                                        : std::string("crashes: ") + strsignal(WTERMSIG(status)));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 10)
    return "MRPT's deserializer itself allocates more than " + std::to_string(kMrptPrecheckMiB) +
           " MiB (a corrupt length field)";
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    return "MRPT's deserializer itself ends the process (status " +
           std::to_string(WEXITSTATUS(status)) + ", a sanitizer report?)";
  return {};
}

/// An observation whose images are stored beside the rawlog (as tum2rawlog --external-images
/// writes them): "<images>/000000_rgb.png" and "<images>/000000_depth.bin". Writes the files.
mrpt::obs::CObservation3DRangeScan::Ptr externalObservation(const std::string& imagesDir) {
  fs::create_directories(imagesDir);
  auto obs = makeObservation(40, 30, 300, 0.0);
  obs->intensityImage.saveToFile(imagesDir + "/000000_rgb.png");
  obs->intensityImage.setExternalStorage("000000_rgb.png");
  obs->rangeImage_convertToExternalStorage("000000_depth.bin", imagesDir + "/");
  return obs;
}

void runRawlog(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string path = ctx.dir + "/input.rawlog";
  writeFileBytes(path, in);
  // The external images the corpus' "external-images" rawlog names.
  if (!fs::exists(ctx.dir + "/input_Images/000000_depth.bin"))
    (void)externalObservation(ctx.dir + "/input_Images");
  // As slamdunk-rawlog does: prefetching reader, every scan through the pipeline, which
  // reports a malformed observation as a lost frame ("unusable observation: ...").
  PrefetchingRawlogReader reader(path);
  SlamSystem slam(fuzzSlamOptions());
  for (int n = 0; n < 4; ++n) {
    const auto obs = reader.next();
    if (!obs) break;
    TrackingResult r;
    try {
      r = slam.process(*obs);
    } catch (const std::exception& e) {
      throw UseFailure(std::string("the pipeline threw on an observation: ") + e.what());
    }
    if (r.lostReason.rfind("unusable observation", 0) == 0)
      ++st.framesRejected;
    else
      ++st.framesAccepted;
    obs->unload();
  }
  slam.finish();
}

// ------------------------------------------------------------------ map

std::shared_ptr<KeyframeGraph> seedGraph(Rng& rng, bool hostileValues, bool images) {
  auto graph = std::make_shared<KeyframeGraph>();
  const int keyframes = 1 + int(rng.below(3));
  auto h = [&](double v) { return hostileValues ? hostile(rng, v, 10) : v; };
  for (int k = 0; k < keyframes; ++k) {
    auto kf = std::make_shared<Keyframe>();
    kf->id = KeyframeId(k);
    kf->timestamp = h(1000.0 + k);
    CameraIntrinsics& K = kf->intrinsics;
    K.width = 16;
    K.height = 12;
    K.fx = h(13.0);
    K.fy = h(13.0);
    K.cx = h(7.5);
    K.cy = h(5.5);
    if (hostileValues && rng.chance(10)) K.width = int(rng.next());
    const int n = int(rng.below(12));
    int descType = CV_32F, descCols = 64;
    if (hostileValues && rng.chance(20)) {
      static const int types[] = {CV_8U, CV_64F, CV_32FC2, CV_16U};
      descType = types[rng.below(4)];
      descCols = 1 + int(rng.below(128));
    }
    kf->features.descriptors.create(n, descCols, descType);
    if (n > 0) cv::randu(kf->features.descriptors, 0, 1);
    for (int i = 0; i < n; ++i) {
      cv::KeyPoint kp(float(rng.uniform(0, 16)), float(rng.uniform(0, 12)), 3.0f);
      if (hostileValues && rng.chance(5)) kp.pt.x = float(interestingDouble(rng));
      kf->features.keypoints.push_back(kp);
      kf->features.points.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), h(1.5));
    }
    if (images) {
      kf->colour = cv::Mat(12, 16, CV_8UC3, cv::Scalar(40, 90, 200));
      kf->depth = cv::Mat(12, 16, CV_32F, cv::Scalar(1.25f));
      if (hostileValues && rng.chance(20))
        kf->depth.at<float>(int(rng.below(12)), int(rng.below(16))) = float(interestingDouble(rng));
      if (hostileValues && rng.chance(10)) kf->colour = cv::Mat(5, 7, CV_16UC4, cv::Scalar(1));
    }
    kf->depthSmallStride = 4;
    cv::Mat small(3, 4, CV_32F, cv::Scalar(1.25f));
    small.convertTo(kf->depthSmall, CV_16F);
    if (hostileValues && rng.chance(15)) {
      static const int strides[] = {0, -1, 1, 1000, 3};
      kf->depthSmallStride = strides[rng.below(5)];
    }
    if (hostileValues && rng.chance(10)) kf->depthSmall = cv::Mat(2, 2, CV_8U, cv::Scalar(3));
    Pose pose = Pose::Identity();
    pose.translation() = Eigen::Vector3d(0.1 * k, 0, h(0.0));
    if (hostileValues && rng.chance(10)) pose.linear() *= h(1.0);
    graph->addKeyframe(std::move(kf), pose);
  }
  for (int k = 1; k < keyframes; ++k) {
    std::vector<PointMatch> matches(1 + rng.below(5));
    for (auto& m : matches) {
      m.pointI = Eigen::Vector3d(rng.uniform(-1, 1), rng.uniform(-1, 1), 1.5);
      m.pointJ = m.pointI + Eigen::Vector3d(0.1, 0, h(0.0));
      m.weight = h(0.9);
    }
    graph->addMatches(KeyframeId(k - 1), KeyframeId(k), matches);
  }
  return graph;
}

Bytes generateMap(Rng& rng) {
  const CKeyframeGraphMap map(seedGraph(rng, true, rng.chance(50)));
  return serialize({&map});
}

void runMap(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string path = ctx.dir + "/input.map";
  writeFileBytes(path, in);
  const auto map = CKeyframeGraphMap::loadFromFile(path);
  try {
    // What slamdunk-render and MRPT viewers do with a map ...
    (void)map->asString();
    (void)map->getAsSimplePointsMap();
    mrpt::opengl::CSetOfObjects vis;
    map->getVisualizationInto(vis);
    // ... and what --load-map does: the pipeline starts from it and relocalizes.
    SlamSystem slam(fuzzSlamOptions(), map->graph());
    for (const auto& obs : mapProbeFrames()) {
      const TrackingResult r = slam.process(*obs);
      r.status == TrackingStatus::Lost ? ++st.framesRejected : ++st.framesAccepted;
    }
    slam.finish();
  } catch (const std::exception& e) {
    throw UseFailure(std::string("a loaded map made a later stage throw: ") + e.what());
  }
}

// ------------------------------------------------------------------ INI

void runIni(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string path = ctx.dir + "/input.ini";
  writeFileBytes(path, in);
  // Every reader of INI files gets the same input (a camera file is no pipeline file): the
  // input counts as accepted when one of them accepts it, and every rejection must be a
  // std::exception naming the file.
  std::string firstError;
  bool accepted = false;
  auto attempt = [&](const char* what, const std::function<void()>& fn) {
    try {
      fn();
      accepted = true;
    } catch (const std::exception& e) {
      const std::string msg = e.what();
      if (msg.find(path) == std::string::npos)
        throw UseFailure(std::string(what) + " rejected the file without naming it: " + msg);
      if (firstError.empty()) firstError = msg;
    }
  };
  attempt("SlamOptions::fromFile", [&] { (void)SlamOptions::fromFile(path); });
  attempt("RgbdCameraCalibration::loadFromIni",
          [&] { (void)RgbdCameraCalibration::loadFromIni(path); });
  attempt("LiveOptions::fromFile", [&] { (void)live::LiveOptions::fromFile(path); });
  // The map plug-in's render options are read by MRPT (CMultiMetricMap) from a config it
  // opened itself: this reader only knows the section, which its errors must name.
  // A file MRPT's parser refuses never reaches it (the readers above reported that).
  const std::string section = "map_keyframeGraphMap_00_renderOpts";
  std::unique_ptr<mrpt::config::CConfigFile> cfg;
  try {
    cfg = std::make_unique<mrpt::config::CConfigFile>(path);
  } catch (const std::exception&) {
  }
  try {
    if (cfg && cfg->sectionExists(section)) {
      CKeyframeGraphMap::TRenderOptions opts;
      opts.loadFromConfigFile(*cfg, section);
      accepted = true;
    }
  } catch (const std::exception& e) {
    const std::string msg = e.what();
    if (msg.find(section) == std::string::npos && msg.find(path) == std::string::npos)
      throw UseFailure("TRenderOptions rejected a section without naming it: " + msg);
    ++st.useErrors;
  }
  if (!accepted) throw std::runtime_error(firstError);
}

// ------------------------------------------------------------------ TUM trajectory

const Trajectory& referenceTrajectory() {
  static const Trajectory t = [] {
    Trajectory out;
    for (int k = 0; k < 20; ++k) {
      StampedPose sp;
      sp.timestamp = 1000.0 + 0.1 * k;
      sp.pose = poseFromTranslationQuaternion(0.05 * k, 0.01 * k, 0, 0, 0.02 * k, 0, 1);
      out.push_back(sp);
    }
    return out;
  }();
  return t;
}

void runTrajectory(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string path = ctx.dir + "/input.txt";
  writeFileBytes(path, in);
  const Trajectory traj = readTumTrajectory(path);
  // What evaluate-trajectory and --gt do next; too few pairs is an ordinary error there.
  for (int k = 0; k < 2; ++k) {
    try {
      const auto ev = k == 0 ? eval::TrajectoryMetrics::evaluate(traj, referenceTrajectory())
                             : eval::TrajectoryMetrics::evaluate(referenceTrajectory(), traj);
      if (!std::isfinite(ev.ate.stats.rmse))
        throw UseFailure("ATE of an accepted trajectory is not finite");
    } catch (const UseFailure&) {
      throw;
    } catch (const std::exception&) {
      ++st.useErrors;
    }
  }
}

// ------------------------------------------------------------------ TUM folders

/// Writes the fixed images of the TUM folder targets (once per scratch folder).
void prepareTumFolder(const std::string& seq) {
  if (fs::exists(seq + "/rgb/1.png")) return;
  fs::create_directories(seq + "/rgb");
  fs::create_directories(seq + "/depth");
  for (int k = 1; k <= 3; ++k) {
    cv::Mat colour(6, 8, CV_8UC3, cv::Scalar(30 * k, 60, 90));
    cv::Mat depth(6, 8, CV_16U, cv::Scalar(5000 + 100 * k));
    cv::imwrite(seq + "/rgb/" + std::to_string(k) + ".png", colour);
    cv::imwrite(seq + "/depth/" + std::to_string(k) + ".png", depth);
  }
}

RgbdCameraCalibration tumCalibration(uint64_t variant) {
  RgbdCameraCalibration c;
  c.intrinsics.width = 8;
  c.intrinsics.height = 6;
  c.intrinsics.fx = c.intrinsics.fy = 7.0;
  c.intrinsics.cx = 3.5;
  c.intrinsics.cy = 2.5;
  if (variant & 1) {  // depth from a camera of its own: registered to colour
    CameraIntrinsics d = c.intrinsics;
    d.fx = d.fy = 6.0;
    c.depthCamera = d;
    c.colourCentreInDepth = Eigen::Vector3d(0.025, 0, 0);
    c.depthToColourRotation = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  }
  return c;
}

void convertTum(const std::string& seq, const RunContext& ctx) {
  TumToRawlogOptions o;
  o.sequenceFolder = seq;
  o.rawlogPath = ctx.dir + "/out.rawlog";
  o.calibration = tumCalibration(ctx.variant);
  o.externalImages = (ctx.variant >> 1) & 1;
  o.groundTruthObservations = (ctx.variant >> 2) & 1;
  o.maxFrames = 4;
  (void)convertTumToRawlog(o);
}

/// A TUM folder's lists in one file: sections start with "#== rgb.txt", "#== depth.txt" or
/// "#== groundtruth.txt" (comments to the TUM readers, so a whole bundle is a valid list).
void writeBundle(const Bytes& in, const std::string& seq) {
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt"}) fs::remove(seq + "/" + f);
  std::string text(in.begin(), in.end()), current;
  std::map<std::string, std::string> files;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    end = end == std::string::npos ? text.size() : end + 1;
    const std::string line = text.substr(at, end - at);
    if (line.rfind("#== ", 0) == 0) {
      std::string name = line.substr(4);
      while (!name.empty() && (name.back() == '\n' || name.back() == '\r')) name.pop_back();
      current = name;
    }
    if (current == "rgb.txt" || current == "depth.txt" || current == "groundtruth.txt")
      files[current] += line;
    at = end;
  }
  for (const auto& [name, content] : files) writeText(seq + "/" + name, content);
}

void runTumList(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string seq = ctx.dir + "/seq";
  prepareTumFolder(seq);
  writeBundle(in, seq);
  convertTum(seq, ctx);  // tum2rawlog: TumSequence, loadObservation per frame, ground truth
  ++st.framesAccepted;
}

void runDepthPng(const Bytes& in, const RunContext& ctx, RunStats& st) {
  const std::string seq = ctx.dir + "/seq";
  prepareTumFolder(seq);
  writeText(seq + "/rgb.txt", "1.0 rgb/1.png\n");
  writeText(seq + "/depth.txt", "1.0 depth/input.png\n");
  fs::remove(seq + "/groundtruth.txt");
  writeFileBytes(seq + "/depth/input.png", in);
  convertTum(seq, ctx);
  ++st.framesAccepted;
}

/// Depth images of every shape a PNG can take: mostly 16-bit single channel (sometimes of the
/// wrong size), else other depths and channel counts, with zeros and the largest values.
Bytes generateDepthPng(Rng& rng) {
  static const int types[] = {CV_16UC1, CV_16UC1, CV_16UC1, CV_8UC1,
                              CV_8UC3,  CV_16UC3, CV_16UC4, CV_8UC4};
  const int type = types[rng.below(8)];
  const bool right = rng.chance(60);
  const int rows = right ? 6 : 1 + int(rng.below(64)), cols = right ? 8 : 1 + int(rng.below(64));
  cv::Mat m(rows, cols, type);
  cv::randu(m, 0, 65536);
  if (rng.chance(30)) m.setTo(0);
  if (rng.chance(30)) m.setTo(cv::Scalar::all(65535));
  std::vector<uchar> png;
  cv::imencode(".png", m, png);
  return Bytes(png.begin(), png.end());
}

std::string fileName(const std::string& dir, const char* name) { return dir + "/" + name; }

std::vector<Target> makeTargets() {
  std::vector<Target> t;
  t.push_back({"rawlog", "rawlog", InputKind::Binary, true, false, generateRawlog,
               [](const std::string& d) { return fileName(d, "input.rawlog"); }, rawlogMrptPrecheck,
               runRawlog});
  t.push_back({"map",
               "map",
               InputKind::Binary,
               true,
               false,
               generateMap,
               [](const std::string& d) { return fileName(d, "input.map"); },
               {},
               runMap});
  t.push_back({"ini",
               "ini",
               InputKind::Text,
               false,
               false,
               {},
               [](const std::string& d) { return fileName(d, "input.ini"); },
               {},
               runIni});
  t.push_back({"tum-list",
               "txt",
               InputKind::Text,
               false,
               false,
               {},
               [](const std::string& d) { return fileName(d, "seq"); },
               {},
               runTumList});
  t.push_back({"tum-trajectory",
               "txt",
               InputKind::Text,
               false,
               false,
               {},
               [](const std::string& d) { return fileName(d, "input.txt"); },
               {},
               runTrajectory});
  t.push_back({"depth-png",
               "png",
               InputKind::Binary,
               false,
               true,
               generateDepthPng,
               [](const std::string& d) { return fileName(d, "seq/depth/input.png"); },
               {},
               runDepthPng});
  return t;
}

}  // namespace

const std::vector<Target>& allTargets() {
  static const std::vector<Target> t = makeTargets();
  return t;
}

const Target* findTarget(const std::string& name) {
  for (const Target& t : allTargets())
    if (t.name == name) return &t;
  return nullptr;
}

bool isUseFailure(const std::exception& e) { return dynamic_cast<const UseFailure*>(&e); }

// ------------------------------------------------------------------ seed corpus

void makeCorpus(const std::string& dir) {
  for (const Target& t : allTargets()) fs::create_directories(dir + "/" + t.name);

  // rawlog: 3 frames of 40x30 (observation-only format) ...
  {
    std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> obs;
    for (int k = 0; k < 3; ++k) obs.push_back(makeObservation(40, 30, 100 + k, 0.033 * k));
    writeGz(dir + "/rawlog/frames-40x30.rawlog",
            serialize({obs[0].get(), obs[1].get(), obs[2].get()}));
    // ... the same in the action / sensory-frame format with a pose observation ...
    std::vector<mrpt::serialization::CSerializable::Ptr> keep;
    for (int k = 0; k < 2; ++k) {
      auto sf = mrpt::obs::CSensoryFrame::Create();
      sf->insert(obs[size_t(k)]);
      sf->insert(poseObservation());
      keep.push_back(mrpt::obs::CActionCollection::Create());
      keep.push_back(sf);
    }
    writeGz(dir + "/rawlog/sensory-frames.rawlog",
            serialize({keep[0].get(), keep[1].get(), keep[2].get(), keep[3].get()}));
    // ... and two frames whose depth camera (32x24) is not the colour camera: registered.
    auto a = makeObservation(40, 30, 200, 0), b = makeObservation(40, 30, 201, 0.033);
    for (auto* o : {a.get(), b.get()}) {
      o->rangeImage_setSize(24, 32);
      for (int r = 0; r < 24; ++r)
        for (int c = 0; c < 32; ++c) o->rangeImage(r, c) = uint16_t(1500 + 7 * c);
      o->cameraParams.ncols = 32;
      o->cameraParams.nrows = 24;
      o->cameraParams.setIntrinsicParamsFromValues(28, 28, 15.5, 11.5);
      o->relativePoseIntensityWRTDepth =
          mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0)) +
          mrpt::poses::CPose3D(0, -0.025, 0, 0, 0, 0);
    }
    writeGz(dir + "/rawlog/registered-depth.rawlog", serialize({a.get(), b.get()}));
    // ... and one whose images are stored outside (the target provides the image files).
    const std::string tmp = (fs::temp_directory_path() / "fuzz-readers-corpus-images").string();
    auto ext = externalObservation(tmp);
    writeGz(dir + "/rawlog/external-images.rawlog", serialize({ext.get()}));
    fs::remove_all(tmp);
  }
  // map: keyframes with features, edges and subsampled depth; one map also keeps images.
  {
    Rng rng(11);
    const CKeyframeGraphMap features(seedGraph(rng, false, false));
    writeGz(dir + "/map/features-only.map", serialize({&features}));
    const CKeyframeGraphMap images(seedGraph(rng, false, true));
    writeGz(dir + "/map/with-images.map", serialize({&images}));
  }
  // depth-png: the 16-bit depth of a TUM folder (8x6, the calibration of the TUM targets).
  {
    cv::Mat depth(6, 8, CV_16U);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 8; ++c) depth.at<uint16_t>(r, c) = uint16_t(5000 + 250 * r + 30 * c);
    depth.at<uint16_t>(0, 0) = 0;
    cv::imwrite(dir + "/depth-png/depth-8x6.png", depth);
  }
  // tum-list: a TUM folder's lists (see writeBundle) naming the images the target provides.
  writeText(dir + "/tum-list/three-frames.txt",
            "#== rgb.txt\n# color images\n# timestamp filename\n"
            "1305031102.175304 rgb/1.png\n1305031102.211214 rgb/2.png\n"
            "1305031102.243211 rgb/3.png\n"
            "#== depth.txt\n# depth maps\n# timestamp filename\n"
            "1305031102.160407 depth/1.png\n1305031102.194330 depth/2.png\n"
            "1305031102.226738 depth/3.png\n"
            "#== groundtruth.txt\n# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
            "1305031102.1758 1.3405 0.6266 1.6575 0.6574 0.6126 -0.2949 -0.3248\n"
            "1305031102.2158 1.3303 0.6256 1.6464 0.6579 0.6161 -0.2932 -0.3189\n"
            "1305031102.2458 1.3160 0.6254 1.6302 0.6609 0.6199 -0.2893 -0.3086\n");
  writeText(dir + "/tum-list/no-groundtruth.txt",
            "#== rgb.txt\n1.000 rgb/1.png\n1.033 rgb/2.png\n"
            "#== depth.txt\n1.001 depth/1.png\n1.030 depth/2.png\n");
  // tum-trajectory: an estimate as slamdunk-rawlog writes it, and a ground truth with commas.
  {
    std::string text = "# slamdunk-rawlog: every tracked frame\n# timestamp tx ty tz qx qy qz qw\n";
    char line[160];
    for (int k = 0; k < 12; ++k) {
      const double a = 0.02 * k;
      std::snprintf(line, sizeof line, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                    1000.0 + 0.1 * k, 0.05 * k, 0.01 * k, 0.002 * k, 0.0, std::sin(a / 2), 0.0,
                    std::cos(a / 2));
      text += line;
    }
    writeText(dir + "/tum-trajectory/estimate.txt", text);
    writeText(dir + "/tum-trajectory/groundtruth-commas.txt",
              "# ground truth trajectory\n"
              "1000.0,0,0,0,0,0,0,1\n1000.1,0.05,0.01,0,0,0.0099998,0,0.99995\n"
              "1000.2,0.1,0.02,0,0,0.019999,0,0.9998\n1000.3,0.15,0.03,0,0,0.029996,0,0.99955\n");
  }
  // ini: the render options section (the other INI seeds are the repository's own files).
  writeText(dir + "/ini/map-render-options.ini",
            "[map_keyframeGraphMap_00_renderOpts]\ncloud_decimation = 4\nmax_depth = 4.0\n"
            "point_size = 2\nshow_points = true\nshow_frustums = true\nshow_edges = false\n"
            "frustum_size = 0.1\n");
}

}  // namespace slamdunk::fuzz
