// Hostile input through both apps: timestamps that repeat or go backwards (such frames are
// skipped with a warning naming them; the trajectory stays a valid TUM file), and observations
// whose images disagree in size with their intrinsics (skipped as lost, the reason naming the
// frame and both sizes). Rawlogs are edited copies of the prepared synthetic sweep.

#include <slamdunk/core/TumTrajectory.h>

#include "EditedRawlog.h"
#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/system/datetime.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

struct AppRun {
  test::CommandResult result;
  std::string trajectory, frameLog;
  double value(const std::string& key) const { return test::jsonValue(result.output, key); }
  /// Each key of its --json summary has the value given.
  void expectValues(const std::vector<std::pair<std::string, double>>& expected) const {
    for (const auto& [key, v] : expected) EXPECT_EQ(value(key), v) << key << "\n" << result.output;
  }
};

/// slamdunk-rawlog on `rawlog`, outputs in `dir`, with a frame log.
AppRun runRawlogApp(const std::string& rawlog, const std::string& dir,
                    const std::string& extra = "") {
  AppRun r;
  r.trajectory = dir + "/trajectory.txt";
  r.frameLog = dir + "/frames.csv";
  r.result =
      test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --trajectory " +
                       q(r.trajectory) + " --frame-log " + q(r.frameLog) + " " + extra);
  return r;
}

/// slamdunk-live replaying `rawlog` in real time. The queue holds every frame, so none is
/// dropped even where tracking is slow (sanitizers): each frame's treatment is what is tested.
AppRun runLiveApp(const std::string& rawlog, const std::string& dir,
                  const std::string& extra = "") {
  AppRun r;
  r.trajectory = dir + "/live-trajectory.txt";
  r.frameLog = dir + "/live-frames.csv";
  const std::string ini = dir + "/live.ini";
  std::ofstream(ini) << "[slamdunk-live]\nsource = REPLAY\nqueue_capacity = 1000\n"
                        "[REPLAY]\ndriver = replay\nrawlog = "
                     << rawlog << "\n";
  r.result =
      test::runCommand(test::toolPath("slamdunk-live") + " --config " + q(ini) + " --trajectory " +
                       q(r.trajectory) + " --frame-log " + q(r.frameLog) + " " + extra);
  return r;
}

/// A valid TUM file whose stamps strictly increase; returns it.
Trajectory expectIncreasingTum(const std::string& path) {
  const Trajectory t = readTumTrajectory(path);  // throws on anything malformed
  for (size_t i = 1; i < t.size(); ++i)
    EXPECT_GT(t[i].timestamp, t[i - 1].timestamp) << path << ": pose " << i;
  return t;
}

double stampOf(const mrpt::obs::CObservation3DRangeScan& o) {
  return mrpt::Clock::toDouble(o.timestamp);
}

}  // namespace

// ------------------------------------------------------------------ timestamps

namespace {
/// 60 frames of the sweep; frame 20 repeats frame 19's stamp, frame 40 goes back to frame 30's.
std::string rawlogWithBadStamps(const std::string& src, const std::string& dir) {
  const std::string out = dir + "/stamps.rawlog";
  std::vector<double> stamps;
  test::writeEditedRawlog(src, out, 60, [&](size_t i, mrpt::obs::CObservation3DRangeScan& o) {
    stamps.push_back(stampOf(o));
    if (i == 20) o.timestamp = mrpt::Clock::fromDouble(stamps[19]);
    if (i == 40) o.timestamp = mrpt::Clock::fromDouble(stamps[30]);
  });
  return out;
}
}  // namespace

// Decided behaviour: a frame whose stamp is not after the last processed frame's is skipped
// (not tracked, not counted lost) with a warning naming it and both stamps. Processing it would
// put two poses at one instant, or one in the past, in the trajectory (not a valid TUM file,
// ambiguous for evaluation) and give the motion model a zero or negative time step.
TEST(HostileInput, RepeatedOrBackwardTimestampsAreSkippedOffline) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("Hostile_StampsOffline");
  const AppRun r = runRawlogApp(rawlogWithBadStamps(src, dir), dir, "--json");
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  r.expectValues({{"frames_out_of_order", 2}, {"frames", 58}, {"tracked", 58}, {"lost", 0}});
  for (const char* warning : {"warning: frame 20: timestamp ", "is not after frame 19's",
                              "warning: frame 40: timestamp ", "is not after frame 39's"})
    EXPECT_NE(r.result.output.find(warning), std::string::npos) << warning << r.result.output;
  EXPECT_EQ(expectIncreasingTum(r.trajectory).size(), 58u);
  const auto status = test::csvColumn(r.frameLog, "status");
  ASSERT_EQ(status.size(), 60u);
  for (size_t i = 0; i < status.size(); ++i)
    EXPECT_EQ(status[i], i == 20 || i == 40 ? "skipped" : (i == 0 ? "initialized" : "tracked"))
        << "frame " << i;
}

TEST(HostileInput, RepeatedOrBackwardTimestampsAreSkippedLive) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("Hostile_StampsLive");
  const AppRun r = runLiveApp(rawlogWithBadStamps(src, dir), dir, "--json -q");
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  r.expectValues({{"frames_received", 60}, {"frames_processed", 60}, {"frames_out_of_order", 2}});
  EXPECT_EQ(r.value("tracked") + r.value("lost"), 58) << r.result.output;
  const Trajectory t = expectIncreasingTum(r.trajectory);
  EXPECT_EQ(t.size(), r.value("tracked"));
  EXPECT_GE(t.size(), 55u);
  const auto status = test::csvColumn(r.frameLog, "status");
  ASSERT_EQ(status.size(), 60u);
  EXPECT_EQ(status[20], "skipped");
  EXPECT_EQ(status[40], "skipped");
  // The text summary names the skipped frames.
  const AppRun text = runLiveApp(dir + "/stamps.rawlog", dir, "-q");
  ASSERT_EQ(text.result.exitCode, 0) << text.result.output;
  EXPECT_NE(text.result.output.find("skipped:       2 frames whose timestamp did not increase"),
            std::string::npos)
      << text.result.output;
  EXPECT_NE(text.result.output.find("frame 40: timestamp "), std::string::npos)
      << text.result.output;
}

// ------------------------------------------------------------------ image sizes

namespace {
/// 30 frames of the sweep (640x480, intrinsics for 640x480) with three inconsistent ones:
/// frame 10's colour is 320x240, frame 12's colour and depth are both 320x240 (consistent with
/// each other, not with the intrinsics: the case that used to be tracked with the 640x480 focal
/// length and centre), frame 14's intrinsics say 1280x960.
std::string rawlogWithWrongSizes(const std::string& src, const std::string& dir) {
  const std::string out = dir + "/sizes.rawlog";
  auto halveColour = [](mrpt::obs::CObservation3DRangeScan& o) {
    cv::Mat small;
    cv::resize(o.intensityImage.asCvMatRef(), small, cv::Size(320, 240), 0, 0, cv::INTER_AREA);
    o.intensityImage = mrpt::img::CImage(small, mrpt::img::DEEP_COPY);
  };
  test::writeEditedRawlog(src, out, 30, [&](size_t i, mrpt::obs::CObservation3DRangeScan& o) {
    if (i == 10) halveColour(o);
    if (i == 12) {
      halveColour(o);
      const mrpt::math::CMatrix_u16 full = o.rangeImage;
      o.rangeImage_setSize(240, 320);
      for (int r = 0; r < 240; ++r)
        for (int c = 0; c < 320; ++c) o.rangeImage(r, c) = full(2 * r, 2 * c);
    }
    if (i == 14) {
      o.cameraParamsIntensity.ncols = 1280;
      o.cameraParamsIntensity.nrows = 960;
    }
  });
  return out;
}

void expectSizesNamed(const std::string& output) {
  for (const char* text :
       {"colour image is 320x240 but its intrinsics (cameraParamsIntensity) are for 640x480",
        "colour image is 640x480 but its intrinsics (cameraParamsIntensity) are for 1280x960"})
    EXPECT_NE(output.find(text), std::string::npos) << text << "\n" << output;
}
}  // namespace

TEST(HostileInput, ImagesOfAnotherSizeThanTheirIntrinsicsAreSkippedNamingTheSizes) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("Hostile_Sizes");
  const std::string rawlog = rawlogWithWrongSizes(src, dir);
  const AppRun r = runRawlogApp(rawlog, dir);
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  // Each frame is named, by index and timestamp, with both sizes.
  for (const char* frame : {"frame 10 (t=", "frame 12 (t=", "frame 14 (t="})
    EXPECT_NE(r.result.output.find(frame), std::string::npos) << frame << r.result.output;
  expectSizesNamed(r.result.output);
  const auto status = test::csvColumn(r.frameLog, "status");
  ASSERT_EQ(status.size(), 30u);
  for (size_t i = 1; i < status.size(); ++i)
    EXPECT_EQ(status[i], i == 10 || i == 12 || i == 14 ? "lost" : "tracked") << "frame " << i;
  EXPECT_EQ(expectIncreasingTum(r.trajectory).size(), 27u);

  // Live: the same frames are lost, the summary names the problem.
  const AppRun live = runLiveApp(rawlog, dir, "-q");
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  expectSizesNamed(live.result.output);
  EXPECT_EQ(expectIncreasingTum(live.trajectory).size(), 27u) << live.result.output;
}
