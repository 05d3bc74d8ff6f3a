// apps::RawlogSlamRun driven as an application drives it: the same outputs as slamdunk-rawlog,
// the callbacks on every frame, the frame log's columns, the figures of the summary.

#include <slamdunk/apps/RawlogSlamRun.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/features/FramePreparation.h>

#include "TestData.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using namespace slamdunk;
using namespace slamdunk::apps;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// A frame log's line without its timings (the columns whose names start with "ms_").
std::string withoutTimings(const std::string& header, const std::string& line) {
  std::stringstream names(header), values(line);
  std::string out;
  for (std::string name, value; std::getline(names, name, ',');) {
    std::getline(values, value, ',');
    if (name.rfind("ms_", 0) != 0) out += value + ",";
  }
  return out;
}

}  // namespace

// The class writes what the program writes: the same trajectory, keyframes and frame log (but
// for its timing columns), from the same options.
TEST(RawlogSlamRun, WritesWhatSlamdunkRawlogWrites) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("RawlogSlamRun_AsTheApp");
  RawlogRunOptions o;
  o.rawlog = rawlog;
  o.groundTruth = test::groundTruthOf(rawlog);
  o.maxFrames = 60;
  o.trajectory = dir + "/class.txt";
  o.frameLog = dir + "/class.csv";
  size_t framesSeen = 0, pauses = 0;
  RawlogSlamRun run(o);
  run.onFrame([&](const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult&) {
    EXPECT_TRUE(obs.hasRangeImage);
    ++framesSeen;
  });
  run.beforeFrame([&](size_t framesDone) {
    EXPECT_EQ(framesDone, pauses++);
    if (framesDone == 10) std::this_thread::sleep_for(std::chrono::milliseconds(300));
  });
  const auto start = std::chrono::steady_clock::now();
  const RawlogRunResult result = run.run();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  EXPECT_TRUE(result.readError.empty()) << result.readError;
  EXPECT_EQ(framesSeen, 60u);
  EXPECT_EQ(pauses, 60u);
  EXPECT_EQ(result.figures.stats.frames, 60u);
  EXPECT_EQ(result.figures.stats.lost, 0u);
  ASSERT_TRUE(result.figures.ate);
  EXPECT_LT(result.figures.ate->rmse, 0.005);
  EXPECT_LE(result.figures.wallSeconds, seconds - 0.3) << "the pause counted in the run's speed";

  const test::CommandResult app = test::runCommand(
      test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " -q --max-frames 60 --trajectory " +
      q(dir + "/app.txt") + " --frame-log " + q(dir + "/app.csv"));
  ASSERT_EQ(app.exitCode, 0) << app.output;
  EXPECT_EQ(test::readFile(dir + "/class.txt"), test::readFile(dir + "/app.txt"));
  EXPECT_EQ(test::readFile(dir + "/class_keyframes.txt"),
            test::readFile(dir + "/app_keyframes.txt"));
  const auto classLog = lines(dir + "/class.csv"), appLog = lines(dir + "/app.csv");
  ASSERT_EQ(classLog.size(), 61u);
  ASSERT_EQ(appLog.size(), 61u);
  EXPECT_EQ(classLog[0], FrameCsvLog::kHeader);
  EXPECT_EQ(appLog[0], FrameCsvLog::kHeader);
  for (size_t i = 1; i < classLog.size(); ++i)
    EXPECT_EQ(withoutTimings(classLog[0], classLog[i]), withoutTimings(appLog[0], appLog[i]))
        << "line " << i;
}

// An output over an input is refused before anything is read or written, naming both.
TEST(RawlogSlamRun, RefusesAnOutputOverAnInput) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("RawlogSlamRun_Clash");
  const std::string gt = dir + "/gt.txt";
  fs::copy_file(test::groundTruthOf(rawlog), gt, fs::copy_options::overwrite_existing);
  RawlogRunOptions o;
  o.rawlog = rawlog;
  o.groundTruth = gt;
  o.trajectory = dir + "/t.txt";
  o.frameLog = gt;
  try {
    RawlogSlamRun run(o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--frame-log '" + gt + "' is the input --gt"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(test::readFile(gt), test::readFile(test::groundTruthOf(rawlog)));
}

namespace {

struct PreparedAheadRun {
  size_t keyframes = 0;
  size_t turnedKeyframes = 0;  ///< keyframes whose descriptor windows were turned
  std::string brokenReason;
};

/// Tracks the first `count` observations of `rawlog` one by one, then prepared ahead
/// (FramePrefetcher, as RawlogSlamRun runs), observation `broken` stripped of its depth; expects
/// the same features, results and trajectory, bit for bit.
PreparedAheadRun expectPreparedAheadTrackedAsObservations(const std::string& rawlog, size_t count,
                                                          size_t broken) {
  std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> observations;
  {
    PrefetchingRawlogReader reader(rawlog);
    while (observations.size() < count) observations.push_back(reader.next());
  }
  auto noDepth = selfContainedCopy(*observations[broken]);
  noDepth->hasRangeImage = false;
  observations[broken] = noDepth;

  const SlamOptions options;
  SlamSystem oneByOne(options);
  std::vector<TrackingResult> expected;
  for (const auto& obs : observations) expected.push_back(oneByOne.process(*obs));
  oneByOne.finish();

  const FeatureExtractor extractor(options.features);
  SlamSystem prepared(options);
  size_t next = 0;
  FramePrefetcher frames(
      [&] { return next < observations.size() ? observations[next++] : nullptr; },
      options.features);
  PreparedAheadRun run;
  for (size_t i = 0;; ++i) {
    std::optional<PreparedFrame> frame = frames.next();
    if (!frame) {
      EXPECT_EQ(i, observations.size());
      break;
    }
    EXPECT_LT(i, observations.size());
    if (i >= observations.size()) break;
    EXPECT_EQ(frame->observation, observations[i]) << "frame " << i << " out of order";
    if (i == broken) {
      EXPECT_FALSE(frame->frame.has_value());
      EXPECT_NE(frame->error.find("has no depth"), std::string::npos) << frame->error;
    } else {
      const FeatureSet own = extractor.extract(RgbdFrame::fromObservation(*observations[i]));
      EXPECT_EQ(frame->features.size(), own.size()) << "frame " << i;
      if (frame->features.size() != own.size()) break;
      EXPECT_EQ(cv::norm(frame->features.descriptors, own.descriptors, cv::NORM_INF), 0.0);
      EXPECT_EQ(frame->features.points, own.points) << "frame " << i;
    }
    const TrackingResult r = prepared.process(std::move(*frame));
    EXPECT_EQ(r.status, expected[i].status) << "frame " << i;
    EXPECT_EQ(r.lostReason, expected[i].lostReason) << "frame " << i;
    EXPECT_EQ(r.newKeyframe, expected[i].newKeyframe) << "frame " << i;
  }
  prepared.finish();

  const Trajectory a = oneByOne.trajectory(), b = prepared.trajectory();
  EXPECT_EQ(a.size(), count - 1);
  EXPECT_EQ(b.size(), a.size());
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    EXPECT_EQ(a[i].timestamp, b[i].timestamp);
    EXPECT_TRUE(a[i].pose.matrix() == b[i].pose.matrix()) << "pose " << i;
  }
  EXPECT_EQ(prepared.statistics().keyframes, oneByOne.statistics().keyframes);
  run.keyframes = prepared.statistics().keyframes;
  for (KeyframeId id : prepared.graph()->ids())
    if (prepared.graph()->keyframe(id)->features.keypoints.front().angle >= 0)
      ++run.turnedKeyframes;
  run.brokenReason = expected[broken].lostReason;
  return run;
}

}  // namespace

// Frames prepared ahead (FramePrefetcher, as RawlogSlamRun runs) carry the features the
// tracker would extract itself, and are tracked to the same trajectory, bit for bit, as their
// observations given one by one (a real recording); an unusable observation among them is
// reported the same way.
TEST(RawlogSlamRun, FramesPreparedAheadAreTrackedAsTheirObservations) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f");
  const PreparedAheadRun run = expectPreparedAheadTrackedAsObservations(rawlog, 100, 20);
  EXPECT_EQ(run.brokenReason.rfind("unusable observation: ", 0), 0u) << run.brokenReason;
  EXPECT_GE(run.keyframes, 4u);
}

// A rolling hand-held camera: frames prepared ahead (upright) are described again, turned, by
// the tracker; frames given one by one are described turned at once. Both are tracked alike.
TEST(RawlogSlamRun, FramesOfARollingCameraPreparedAheadAreTrackedAsTheirObservations) {
  REQUIRE_RAWLOG(rawlog, "handheld_dwell16s_kinect");
  const PreparedAheadRun run = expectPreparedAheadTrackedAsObservations(rawlog, 200, 100);
  std::printf("%zu of %zu keyframes described turned\n", run.turnedKeyframes, run.keyframes);
  EXPECT_GE(run.turnedKeyframes, 2u);
}
