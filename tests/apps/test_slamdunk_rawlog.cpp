// The offline app end to end: accuracy on synthetic and real sequences, determinism, bad input.
// Rawlogs come from the prepare_test_data fixture (build/test-data); runs that several tests
// check, from the shared_runs fixture (build/shared-runs, tests/apps/CMakeLists.txt).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/TumTrajectory.h>

#include "EditedRawlog.h"
#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/datetime.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <tuple>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

struct SlamRun {
  test::CommandResult result;
  std::string trajectory;
  std::string map;  ///< the saved map, when there is one
  double value(const std::string& key) const { return test::jsonValue(result.output, key); }
};

/// A run that several tests share (tests/apps/CMakeLists.txt, slamdunk_shared_run): it exited 0
/// and saved its map. Skips the test (or fails it, SLAMDUNK_REQUIRE_DATA=1) when it was not made.
#define REQUIRE_SHARED_RUN(var, name)     \
  REQUIRE_SHARED_RUN_DIR(var##Dir, name); \
  const SlamRun var = sharedRun(var##Dir)

SlamRun sharedRun(const std::string& dir) {
  SlamRun r;
  r.result.exitCode = 0;
  r.result.output = test::readFile(dir + "/output.txt");
  r.trajectory = dir + "/trajectory.txt";
  r.map = dir + "/run.map";
  return r;
}

SlamRun runSlam(const std::string& rawlog, const std::string& outDir, const std::string& extra = "",
                bool withGt = true) {
  SlamRun r;
  r.trajectory = outDir + "/trajectory.txt";
  std::string cmd = test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --trajectory " +
                    q(r.trajectory) + " --json -q " + extra;
  if (withGt && fs::exists(test::groundTruthOf(rawlog)))
    cmd += " --gt " + q(test::groundTruthOf(rawlog));
  r.result = test::runCommand(cmd);
  return r;
}

/// Writes an INI with the given overrides of the built-in defaults into dir; returns the
/// "--config FILE" argument for runSlam.
std::string configWith(const std::string& dir, const std::string& iniText) {
  std::ofstream(dir + "/override.ini") << iniText;
  return " --config " + q(dir + "/override.ini");
}

/// The "--config FILE" argument for the shipped default INI (the file users copy).
std::string defaultConfig() {
  return " --config " + q(test::sourceDir() + "/config-ini/slamdunk-default.ini");
}

/// Default run on a prepared sequence: exit 0, no frame lost, ATE below the bound.
SlamRun expectAllTrackedWithin(const std::string& rawlog, const std::string& dirName,
                               double ateBound) {
  SlamRun r = runSlam(rawlog, test::scratchDir(dirName));
  EXPECT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("lost"), 0) << r.result.output;
  EXPECT_LT(r.value("ate_rmse_m"), ateBound) << r.result.output;
  return r;
}

/// Exit 0, every one of `frames` frames tracked, ATE at most `ateBound`.
void expectEveryFrameTracked(const SlamRun& r, int frames, double ateBound) {
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("frames"), frames) << r.result.output;
  EXPECT_EQ(r.value("tracked"), frames) << r.result.output;
  EXPECT_LE(r.value("ate_rmse_m"), ateBound) << r.result.output;
}

/// Runs `args` again with --no-optimization and expects the optimized run `opt` to have a lower
/// ATE, below `share` times the tracking-only run's; returns the tracking-only run.
SlamRun expectOptimizationBeatsTrackingAlone(const std::string& rawlog, const SlamRun& opt,
                                             const std::string& dirName,
                                             const std::string& args = "", double share = 1.0) {
  SlamRun track = runSlam(rawlog, test::scratchDir(dirName), args + " --no-optimization");
  EXPECT_EQ(track.result.exitCode, 0) << track.result.output;
  EXPECT_LT(opt.value("ate_rmse_m"), share * track.value("ate_rmse_m"))
      << "local optimization did not improve enough on tracking alone:\n"
      << opt.result.output << track.result.output;
  return track;
}

using test::readFile;

}  // namespace

// ------------------------------------------------------------------ accuracy

// The shipped INI (SlamOptions.DefaultIniEqualsBuiltInDefaults: the built-in defaults) on the
// loop with exact depth: every frame tracked within 5 mm, the loop closed, and the local
// optimization at least as good as tracking alone within 0.4 mm. There tracking alone is at its
// floor (1.2-1.5 mm over eleven KD-tree seeds) and the optimization ends 0.9-1.25 times it (at
// most 0.31 mm above), with the tree alone deciding which of the two is lower
// (docs/experiments.md). The gain is asserted where there is one, on the Kinect-like loop below.
TEST(SlamdunkRawlog, SyntheticLoopIsAccurateClosesTheLoopAndOptimizationDoesNoHarm) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  REQUIRE_SHARED_RUN(opt, "synthetic_loop");  // the shipped INI
  EXPECT_EQ(opt.value("lost"), 0) << opt.result.output;
  EXPECT_GE(opt.value("loop_closures"), 1) << opt.result.output;
  EXPECT_GE(opt.value("optimizations"), 1) << opt.result.output;
  // Inline, the optimizations take a share of the run (about a quarter here).
  EXPECT_GT(opt.value("optimizer_share"), 0.01) << opt.result.output;
  EXPECT_LT(opt.value("optimizer_share"), 0.9) << opt.result.output;
  EXPECT_LT(opt.value("ate_rmse_m"), 0.005) << opt.result.output;
  const SlamRun track = runSlam(rawlog, test::scratchDir("Slam_SyntheticLoopDefault_NoOpt"),
                                defaultConfig() + " --no-optimization");
  ASSERT_EQ(track.result.exitCode, 0) << track.result.output;
  EXPECT_LT(opt.value("ate_rmse_m"), track.value("ate_rmse_m") + 0.0004)
      << "local optimization made the exact loop worse than tracking alone:\n"
      << opt.result.output << track.result.output;
}

// With the paper's 3D-3D cost (residual_form = edge), weighing edge matches by keypoint scale
// (coarse SURF octaves localise to several pixels) makes the feature-only bundle adjustment more
// precise on the synthetic loop (3.1 -> 2.5 mm measured with the default tracking of then;
// 3.5 -> 2.0 mm with the dense depth term). Off by default: on 7-Scenes it measured worse.
TEST(SlamdunkRawlog, SyntheticLoopScaleAwareEdgeWeightsImproveTheOptimization) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("Slam_SyntheticLoopScaleAware");
  const std::string edgeForm = "[optimizer]\nresidual_form = edge\n";
  const SlamRun scaleAware =
      runSlam(rawlog, dir, configWith(dir, edgeForm + "[tracker]\nkeypoint_scale_sigma = 0.2\n"));
  ASSERT_EQ(scaleAware.result.exitCode, 0) << scaleAware.result.output;
  const std::string plainDir = test::scratchDir("Slam_SyntheticLoopPlainWeights");
  const SlamRun plain = runSlam(rawlog, plainDir, configWith(plainDir, edgeForm));
  ASSERT_EQ(plain.result.exitCode, 0) << plain.result.output;
  EXPECT_LT(scaleAware.value("ate_rmse_m"), 0.9 * plain.value("ate_rmse_m"))
      << scaleAware.result.output << plain.result.output;
  EXPECT_GE(scaleAware.value("loop_closures"), 1) << scaleAware.result.output;
}

// The same loop seen through a simulated Kinect v1 (disparity noise and 1/8-px steps): there
// the local optimization improves on tracking alone by a quarter or more with the default INI
// (0.50-0.77 times its ATE over seven KD-tree seeds, FLANN's or the own tree's); the bound asks
// for 15 %.
TEST(SlamdunkRawlog, SyntheticLoopWithKinectDepthOptimizationBeatsTrackingAlone) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop_kinect");
  const SlamRun opt = expectAllTrackedWithin(rawlog, "Slam_SyntheticLoopKinect", 0.015);
  EXPECT_GE(opt.value("loop_closures"), 1) << opt.result.output;
  expectOptimizationBeatsTrackingAlone(rawlog, opt, "Slam_SyntheticLoopKinect_NoOpt", "", 0.85);
}

// ------------------------------------------------------------------ loop closing

namespace {
/// How far the trajectory's return is off its start, against the ground truth's: the error of
/// the motion from the first pose to the last (scripts/loop-return-error.py), in metres and
/// degrees. Every frame tracked: the first and last poses are the ground truth's first and last.
std::pair<double, double> returnError(const std::string& trajectory, const std::string& rawlog) {
  const Trajectory t = readTumTrajectory(trajectory);
  const Trajectory gt = readTumTrajectory(test::groundTruthOf(rawlog));
  if (t.size() < 2 || gt.size() < 2) return {1e9, 1e9};
  EXPECT_NEAR(t.front().timestamp, gt.front().timestamp, 1e-6);
  EXPECT_NEAR(t.back().timestamp, gt.back().timestamp, 1e-6);
  const Pose estimated = t.front().pose.inverse() * t.back().pose;
  const Pose truth = gt.front().pose.inverse() * gt.back().pose;
  return {translationDistance(estimated, truth), rotationDistance(estimated, truth) * 180 / M_PI};
}

/// The tour with local optimization alone (no place recognition), every frame tracked.
SlamRun withoutLoopClosing(const std::string& rawlog, const std::string& dirName) {
  const std::string dir = test::scratchDir(dirName);
  SlamRun r = runSlam(rawlog, dir, configWith(dir, "[loop_closing]\nenabled = false\n"));
  expectEveryFrameTracked(r, 1100, 1.0);
  EXPECT_EQ(r.value("loop_closures"), 0) << r.result.output;
  return r;
}
}  // namespace

// The office tour through a camera whose stated focal length is 3 % off its true one: the
// odometry drifts by decimetres, and at the return the active window no longer holds the first
// keyframes. Place recognition finds the loop, and its correction at least halves the ATE,
// inline (deterministic: two runs, one trajectory) and on the optimizer's thread. Local
// optimization alone ends at 0.245 m (0.254 m with the paper's keyframe rule): the bound is
// about half of that; the test also checks that the data still need the correction (its return
// 0.2 m or 2 degrees off or more, as issue 46 asks). One of scripts/test-long.sh's
// (SLAMDUNK_LONG_TESTS=1): CI closes the same tour with a bare corridor, below.
TEST(SlamdunkRawlogLoops, PlaceRecognitionClosesTheDriftingOfficeTour) {
  REQUIRE_RAWLOG(rawlog, "tour_drift");
  double bound = 0.125;
  if (test::longTestsEnabled()) {
    const SlamRun local = withoutLoopClosing(rawlog, "Loops_TourDrift_Local");
    const auto [localMetres, localDegrees] = returnError(local.trajectory, rawlog);
    EXPECT_TRUE(localMetres > 0.2 || localDegrees > 2)
        << "the data no longer need a loop correction: the return is " << localMetres << " m and "
        << localDegrees << " degrees off";
    // At the return the window's pool holds the first keyframes 1.1 m off: the frames still
    // register by their features (against the keyframes near their reference), not by depth.
    EXPECT_LE(local.value("tracked_depth_only"), 1) << local.result.output;
    bound = 0.5 * local.value("ate_rmse_m");
  }

  const SlamRun global = runSlam(rawlog, test::scratchDir("Loops_TourDrift"));
  expectEveryFrameTracked(global, 1100, bound);
  EXPECT_GE(global.value("place_loops"), 1) << global.result.output;
  const SlamRun again = runSlam(rawlog, test::scratchDir("Loops_TourDrift_Again"));
  EXPECT_EQ(readFile(global.trajectory), readFile(again.trajectory));

  // CI corrects loops on the back end's thread in SlamdunkLive.ASessionOutsideTheLoadedMapJoinsIt.
  if (!test::longTestsEnabled()) return;
  const std::string threadDir = test::scratchDir("Loops_TourDrift_Thread");
  const SlamRun thread =
      runSlam(rawlog, threadDir, configWith(threadDir, "[slam]\noptimizer_thread = true\n"));
  ASSERT_EQ(thread.result.exitCode, 0) << thread.result.output;
  EXPECT_GE(thread.value("place_loops"), 1) << thread.result.output;
  EXPECT_LT(thread.value("ate_rmse_m"), bound) << thread.result.output;
}

// The drifting tour with the corridor from B to C painted almost plain (7 m where a frame
// finds far fewer features than elsewhere): tracked throughout, and the loop still found and
// closed at its return, inline and deterministically (two runs, one trajectory). Local
// optimization alone ends at 0.189 m (the bound is 0.6 times that), its return 0.2 m or 2
// degrees off or more: checked in the long runs.
TEST(SlamdunkRawlogLoops, ATourWithABareCorridorIsTrackedAndClosed) {
  REQUIRE_RAWLOG(rawlog, "tour_drift_bare");
  double bound = 0.113;
  if (test::longTestsEnabled()) {
    const SlamRun local = withoutLoopClosing(rawlog, "Loops_TourBare_Local");
    const auto [localMetres, localDegrees] = returnError(local.trajectory, rawlog);
    EXPECT_TRUE(localMetres > 0.2 || localDegrees > 2)
        << "the data no longer need a loop correction";
    bound = 0.6 * local.value("ate_rmse_m");
  }

  const SlamRun global = runSlam(rawlog, test::scratchDir("Loops_TourBare"));
  expectEveryFrameTracked(global, 1100, bound);
  EXPECT_GE(global.value("place_loops"), 1) << global.result.output;
  const auto [metres, degrees] = returnError(global.trajectory, rawlog);
  EXPECT_LT(metres, 0.02) << global.result.output;
  EXPECT_LT(degrees, 0.5) << global.result.output;
  const SlamRun again = runSlam(rawlog, test::scratchDir("Loops_TourBare_Again"));
  EXPECT_EQ(readFile(global.trajectory), readFile(again.trajectory));
}

// The office tour with room C built as a copy of room A: the tour sees the same walls and
// boxes in both rooms, 20 m apart. Place recognition verifies loops between them, and the
// drift guard refuses every one; without it they would be taken for one place (checked in the
// long runs, SLAMDUNK_LONG_TESTS=1).
TEST(SlamdunkRawlogLoops, TwinRoomsAreNotTakenForOnePlace) {
  REQUIRE_RAWLOG(rawlog, "tour_twins");
  REQUIRE_SHARED_RUN(r, "tour_twins");
  expectEveryFrameTracked(r, 1100, 0.03);
  EXPECT_EQ(r.value("place_loops"), 0) << r.result.output;
  EXPECT_GE(r.value("place_candidates_refused"), 5) << "the twin rooms no longer look alike";
  if (!test::longTestsEnabled()) return;

  const std::string dir = test::scratchDir("Loops_Twins_NoGuard");
  const SlamRun unguarded =
      runSlam(rawlog, dir, configWith(dir, "[loop_closing]\nmax_drift_share = 100\n"));
  ASSERT_EQ(unguarded.result.exitCode, 0) << unguarded.result.output;
  EXPECT_GE(unguarded.value("place_loops"), 1) << "the test no longer tempts a false loop";
  EXPECT_GT(unguarded.value("ate_rmse_m"), 1.0) << unguarded.result.output;
}

TEST(SlamdunkRawlog, SyntheticSweepIsAccurate) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  expectAllTrackedWithin(rawlog, "Slam_SyntheticSweep", 0.005);
}

// 7-Scenes' ground truth comes from KinectFusion (dense ICP on the depth images) and its colour
// camera has no published calibration (config-ini/cameras/7scenes.ini). Its colour camera's
// rolling shutter (about 25 ms, learned) bends the features on every fast turn: with each
// frame's velocity estimated with its pose, and its depth registered to colour where each
// colour ray lands (not at the nearest depth pixel's projection), the default gives 0.0391 m
// (0.0361-0.0404 m, median 0.0374, over the KD-tree's seeds 1-11; the paper's keyframe rule
// 0.0342-0.0393 m, median 0.0366: which features the approximate search finds moves the
// figure by 10 %, so the bound sits above that spread, not at one seed's figure).
// The camera stays in one room, where the window holds every keyframe: the window's pool is
// held to its budget (without one it grows to about 16,400 features by the last frame), and
// keyframes follow the views covered (75 with the paper's rule, 42 now).
TEST(SlamdunkRawlog, SevenScenesAllTrackedWithinBounds) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  REQUIRE_SHARED_RUN(run, "7scenes");  // the shipped INI
  expectEveryFrameTracked(run, 1000, 0.041);
  EXPECT_LE(run.value("pool_features_max"), 10000);
  EXPECT_LE(run.value("keyframes"), 50) << run.result.output;
}

// The paper's 3D-3D cost (residual_form = edge) on 7-Scenes: within the accuracy issue's bound,
// and its optimization improves on tracking alone.
TEST(SlamdunkRawlog, SevenScenesWithThePapersCost) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("Slam_7ScenesEdge");
  const std::string config =
      configWith(dir,
                 "[optimizer]\nresidual_form = edge\n[tracker]\nestimate_keypoint_noise = "
                 "false\nestimate_rolling_shutter = false\n");
  const SlamRun opt = runSlam(rawlog, dir, config);
  expectEveryFrameTracked(opt, 1000, 0.038);
  expectOptimizationBeatsTrackingAlone(rawlog, opt, "Slam_7ScenesEdge_NoOpt", config);
}

// Real hand-held motion with motion-capture ground truth (TUM fr1/xyz, first 400 frames).
// ORB-SLAM2 gives 0.0106 m on these frames on this machine; SlamDunk 0.0073 m (README): the
// landmark bundle adjustment and what the tracker learns of the Kinect (its features' noise,
// its 25 ms rolling-shutter readout) took it from 0.015 m.
TEST(SlamdunkRawlog, TumFr1XyzHandHeld) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f");
  expectEveryFrameTracked(runSlam(rawlog, test::scratchDir("Slam_Fr1Xyz"), defaultConfig()), 394,
                          0.010);
}

// fr1_xyz_400f's 394 associated pairs thinned by tum2rawlog --stride: all of them tracked, ATE
// <= 0.015 m.
// The same frames at a third of the rate (10 Hz, tum2rawlog --stride 3): three times the
// motion between frames, as a faster hand gives (median 3.7 cm and 1.7 deg, up to 5.5 cm and
// 5 deg). 0.0083-0.0095 m over RANSAC seeds 42-46 (0.0095 at the INI's).
TEST(SlamdunkRawlog, TumFr1XyzAtAThirdOfTheFrameRate) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f_stride3");
  expectEveryFrameTracked(runSlam(rawlog, test::scratchDir("Slam_Fr1XyzStride3"), defaultConfig()),
                          132, 0.015);
}

// At a sixth of the rate (5 Hz, --stride 6): median 7.7 cm and 3.0 deg between frames, up to
// 10.8 cm and 7.8 deg, more than a fast hand moves between frames at 30 Hz. 0.0096-0.0098 m
// over RANSAC seeds 42-46 (0.0098 at the INI's).
TEST(SlamdunkRawlog, TumFr1XyzAtASixthOfTheFrameRate) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f_stride6");
  expectEveryFrameTracked(runSlam(rawlog, test::scratchDir("Slam_Fr1XyzStride6"), defaultConfig()),
                          66, 0.015);
}

TEST(SlamdunkRawlog, TumFr1DeskNineFrames) {
  REQUIRE_RAWLOG(rawlog, "fr1_desk_9f");
  expectEveryFrameTracked(runSlam(rawlog, test::scratchDir("Slam_Fr1Desk")), 9, 0.01);
}

// A textureless box on a plain floor, 0.67 s between frames: the feature tracker registers no
// frame after the first (no RANSAC inliers among the matches, or fewer than 20 features with
// depth), a known failure. What it does must be clear: each later frame lost, with its reason,
// and no pose it does not have (measured: 1 of 58 tracked, the first, at the origin; 57 lost;
// 1 keyframe; no ATE).
TEST(SlamdunkRawlog, TumFr3CabinetWideBaselinesAreAKnownFailure) {
  REQUIRE_RAWLOG(rawlog, "fr3_cabinet_58kf");
  const std::string dir = test::scratchDir("Slam_Cabinet");
  const std::string frameLog = dir + "/frames.csv";
  const SlamRun r = runSlam(rawlog, dir, "--frame-log " + q(frameLog));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  std::cout << "fr3_cabinet_58kf: tracked " << r.value("tracked") << " of " << r.value("frames")
            << ", lost " << r.value("lost") << "\n";
  EXPECT_EQ(r.value("frames"), 58) << r.result.output;
  EXPECT_EQ(r.value("tracked"), 1) << r.result.output;
  EXPECT_EQ(r.value("lost"), 57) << r.result.output;
  EXPECT_EQ(r.value("keyframes"), 1) << r.result.output;
  EXPECT_TRUE(std::isnan(r.value("ate_rmse_m"))) << "an ATE of one pose: " << r.result.output;

  // The first frame starts the map, every other one is reported lost, with the reason.
  const auto status = test::csvColumn(frameLog, "status");
  const auto reason = test::csvColumn(frameLog, "lost_reason");
  ASSERT_EQ(status.size(), 58u);
  ASSERT_EQ(reason.size(), 58u);
  EXPECT_EQ(status[0], "initialized");
  for (size_t i = 1; i < status.size(); ++i) {
    EXPECT_EQ(status[i], "lost") << "frame " << i;
    EXPECT_FALSE(reason[i].empty()) << "frame " << i << " lost without a reason";
  }

  // No false pose: only the tracked frames are in the trajectory, each where the ground truth
  // puts it (in the first frame's world, the map's), within 5 cm.
  const Trajectory t = readTumTrajectory(r.trajectory);
  EXPECT_EQ(t.size(), r.value("tracked")) << r.result.output;
  ASSERT_FALSE(t.empty());
  EXPECT_NEAR(t.front().timestamp, std::stod(test::csvColumn(frameLog, "timestamp").front()), 1e-6)
      << "the first pose is not the first frame's";
  const Trajectory gt = readTumTrajectory(test::groundTruthOf(rawlog));
  ASSERT_FALSE(gt.empty());
  const auto truthAt = [&](double stamp) {
    return std::min_element(gt.begin(), gt.end(),
                            [&](const auto& a, const auto& b) {
                              return std::abs(a.timestamp - stamp) < std::abs(b.timestamp - stamp);
                            })
        ->pose;
  };
  const Pose origin = truthAt(t.front().timestamp).inverse();
  for (const auto& p : t) {
    const Pose truth = origin * truthAt(p.timestamp);
    EXPECT_LT((truth.translation() - p.pose.translation()).norm(), 0.05) << "at " << p.timestamp;
    EXPECT_LT(rotationDistance(truth, p.pose), 0.05) << "at " << p.timestamp;
  }
}

TEST(SlamdunkRawlog, TwoRunsGiveIdenticalTrajectories) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const SlamRun a = runSlam(rawlog, test::scratchDir("Slam_Determinism_A"));
  const SlamRun b = runSlam(rawlog, test::scratchDir("Slam_Determinism_B"));
  ASSERT_EQ(a.result.exitCode, 0) << a.result.output;
  ASSERT_EQ(b.result.exitCode, 0) << b.result.output;
  const std::string ta = readFile(a.trajectory), tb = readFile(b.trajectory);
  EXPECT_GT(ta.size(), 1000u);
  EXPECT_EQ(ta, tb);
}

// The suite's shared run of 7-Scenes' first 300 frames, and this test's own.
TEST(SlamdunkRawlog, TwoRunsGiveIdenticalTrajectoriesOnRealData) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  REQUIRE_SHARED_RUN(a, "7scenes_300");
  const SlamRun b = runSlam(rawlog, test::scratchDir("Slam_Determinism7"), "--max-frames 300");
  ASSERT_EQ(b.result.exitCode, 0) << b.result.output;
  EXPECT_EQ(a.value("frames"), 300) << a.result.output;
  EXPECT_EQ(readFile(a.trajectory), readFile(b.trajectory));
}

// ------------------------------------------------------------------ bad input

TEST(SlamdunkRawlogBadInput, ZeroDepthAndWrongSizeFramesAreLostABlackFrameIsTrackedByDepth) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamBad_ZeroDepth");
  const std::string rawlog = dir + "/damaged.rawlog";
  std::vector<double> damagedStamps;
  double blackStamp = 0;
  test::writeEditedRawlog(src, rawlog, 30, [&](size_t i, mrpt::obs::CObservation3DRangeScan& o) {
    if ((i >= 10 && i < 15) || i == 22) damagedStamps.push_back(mrpt::Clock::toDouble(o.timestamp));
    if (i == 20) blackStamp = mrpt::Clock::toDouble(o.timestamp);
    if (i >= 10 && i < 15) o.rangeImage.fill(0);                           // all-zero depth
    if (i == 20) o.intensityImage.asCvMatRef().setTo(cv::Scalar::all(0));  // black frame
    if (i == 22) o.rangeImage_setSize(240, 320);                           // wrong depth size
  });
  const SlamRun r = runSlam(rawlog, dir, "", false);
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("frames"), 30) << r.result.output;
  EXPECT_EQ(r.value("lost"), 6) << r.result.output;
  EXPECT_EQ(r.value("tracked"), 24) << r.result.output;
  // No features in the black frame, but its depth is fine (an IR sensor sees in the dark).
  EXPECT_EQ(r.value("tracked_depth_only"), 1) << r.result.output;
  const Trajectory t = readTumTrajectory(r.trajectory);
  EXPECT_EQ(t.size(), 24u);
  for (const auto& p : t)
    for (double s : damagedStamps) EXPECT_GT(std::abs(p.timestamp - s), 1e-4);
  const Trajectory gt = readTumTrajectory(test::groundTruthOf(src));
  const auto near = [](const Trajectory& traj, double stamp) {
    return std::find_if(traj.begin(), traj.end(),
                        [&](const auto& p) { return std::abs(p.timestamp - stamp) < 1e-4; });
  };
  const auto black = near(t, blackStamp), truth = near(gt, blackStamp);
  ASSERT_TRUE(black != t.end() && truth != gt.end());
  // The sweep starts at the ground truth's first pose: both are in the same frame.
  const Pose origin = gt.front().pose.inverse();
  EXPECT_LT(((origin * truth->pose).translation() - black->pose.translation()).norm(), 0.01);
}

namespace {
/// The rawlog with the colour of frames [first, last) black: the lights go out, the depth
/// sensor (infrared) keeps working.
std::string withLightsOff(const std::string& src, const std::string& dir, size_t frames,
                          size_t first, size_t last) {
  const std::string out = dir + "/dark.rawlog";
  test::writeEditedRawlog(src, out, frames, [&](size_t i, mrpt::obs::CObservation3DRangeScan& o) {
    if (i >= first && i < last) o.intensityImage.asCvMatRef().setTo(cv::Scalar::all(0));
  });
  return out;
}
}  // namespace

// Two seconds in the dark midway round the loop, where walls, floor and boxes hold the pose:
// carried by depth alone, then the features take over again and the loop still closes.
// With Kinect-like depth (the harder one for depth alone); with exact depth too in the long runs.
TEST(SlamdunkRawlog, SyntheticLoopLightsOffIsTrackedByDepthAlone) {
  for (const char* name : {"synthetic_loop_kinect", "synthetic_loop"}) {
    if (std::string(name) == "synthetic_loop" && !test::longTestsEnabled()) continue;
    SCOPED_TRACE(name);
    REQUIRE_RAWLOG(src, name);
    const std::string dir = test::scratchDir(std::string("Slam_LightsOff_") + name);
    const std::string rawlog = withLightsOff(src, dir, 400, 180, 240);
    fs::copy_file(test::groundTruthOf(src), test::groundTruthOf(rawlog),
                  fs::copy_options::overwrite_existing);
    const std::string frameLog = dir + "/frames.csv";
    const SlamRun r = runSlam(rawlog, dir, "--frame-log " + q(frameLog));
    ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
    EXPECT_EQ(r.value("lost"), 0) << r.result.output;
    // Every dark frame by depth alone (a few more while the features find the map again).
    EXPECT_GE(r.value("tracked_depth_only"), 60) << r.result.output;
    EXPECT_LE(r.value("tracked_depth_only"), 80) << r.result.output;
    const auto depthOnly = test::csvColumn(frameLog, "depth_only");
    ASSERT_EQ(depthOnly.size(), 400u);
    for (size_t i = 180; i < 240; ++i) EXPECT_EQ(depthOnly[i], "1") << "frame " << i;
    const auto ms = test::csvColumn(frameLog, "ms_total");
    std::vector<double> depthOnlyMs;
    for (size_t i = 0; i < ms.size(); ++i)
      if (depthOnly[i] == "1") depthOnlyMs.push_back(std::stod(ms[i]));
    ASSERT_FALSE(depthOnlyMs.empty());
    std::nth_element(depthOnlyMs.begin(), depthOnlyMs.begin() + depthOnlyMs.size() / 2,
                     depthOnlyMs.end());
    std::printf(
        "%s, lights off for frames 180-239: %g of 400 tracked, %g by depth alone "
        "(%.1f ms each, median), ATE %.4f m, %g loop closures\n",
        name, r.value("tracked"), r.value("tracked_depth_only"),
        depthOnlyMs[depthOnlyMs.size() / 2], r.value("ate_rmse_m"), r.value("loop_closures"));
    EXPECT_GE(r.value("loop_closures"), 1) << r.result.output;
    // Same bounds as with the lights on (exact depth 5 mm, Kinect-like depth 3 cm).
    EXPECT_LT(r.value("ate_rmse_m"), std::string(name) == "synthetic_loop" ? 0.005 : 0.03)
        << r.result.output;
  }
}

// Hand-held motion (issue 11): fast rotation sweeps and a shaking hand, through a camera with
// a 10 ms exposure (motion blur), a 20 ms rolling shutter, auto exposure and depth 5 ms after
// colour. Every frame tracked, ATE <= 1 cm with exact depth and <= 2 cm with Kinect-like depth,
// the largest frame-to-frame error under 2 cm and 1 degree, the first frame pair included.
// Returns the run (for what the caller checks of the readout).
SlamRun checkHandHeld(const std::string& trajectory, bool kinect, const std::string& rawlog,
                      const std::string& dir, const std::string& ini) {
  const std::string name = "handheld_" + trajectory + (kinect ? "_kinect" : "");
  const SlamRun r = runSlam(rawlog, dir, configWith(dir, ini));
  EXPECT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("lost"), 0) << r.result.output;
  const double ate = r.value("ate_rmse_m");
  EXPECT_LT(ate, kinect ? 0.02 : 0.01) << r.result.output;
  // Frame to frame: RPE over one frame period (33 ms).
  const auto rpe = test::runCommand(test::toolPath("evaluate-trajectory") + " " +
                                    q(test::groundTruthOf(rawlog)) + " " + q(r.trajectory) +
                                    " --rpe-delta 0.0333 --json");
  EXPECT_EQ(rpe.exitCode, 0) << rpe.output;
  const double maxTrans = test::jsonValue(rpe.output, "rpe_trans_max_m_per_s");
  const double maxRot = test::jsonValue(rpe.output, "rpe_rot_max_deg_per_s");
  std::printf(
      "%s: %g frames tracked, %g keyframes, ATE %.4f m, largest per-frame error %.4f m "
      "%.3f deg, median %.4f m %.3f deg, readout %.2f ms\n",
      name.c_str(), r.value("tracked"), r.value("keyframes"), ate, maxTrans, maxRot,
      test::jsonValue(rpe.output, "rpe_trans_median_m_per_s"),
      test::jsonValue(rpe.output, "rpe_rot_median_deg_per_s"),
      r.value("camera_rolling_shutter_ms"));
  EXPECT_LT(maxTrans, 0.02) << rpe.output;
  EXPECT_LT(maxRot, 1.0) << rpe.output;
  return r;
}

using HandHeldParam = std::tuple<std::string, bool>;  ///< trajectory, Kinect-like depth
std::string handHeldTestName(const ::testing::TestParamInfo<HandHeldParam>& info) {
  return std::get<0>(info.param) + (std::get<1>(info.param) ? "_kinect" : "_exact");
}

/// A test on one of the hand-held sequences (handheld_<trajectory>[_kinect]).
class HandHeldSequence : public ::testing::TestWithParam<HandHeldParam> {
 protected:
  const std::string& trajectory() const { return std::get<0>(GetParam()); }
  bool kinect() const { return std::get<1>(GetParam()); }
  std::string sequence() const { return "handheld_" + trajectory() + (kinect() ? "_kinect" : ""); }
};

// The camera's timing given as its calibration (the readout is learned on from there),
// measured with each frame's velocity estimated: rotations 1.2 / 3.5 mm ATE, 2.5 / 8.9 mm per
// frame; shake 1.8 / 3.7 mm ATE, 6.2 / 10.2 mm per frame; the 2.5-minute scan 2.4 / 7.6 mm ATE,
// 3.4 / 7.7 mm per frame (its first 20 s, CI's: 1.5 / 3.2 mm ATE, 3.3 / 3.9 mm). With the motion
// between frames extrapolated instead, the shake's first pair erred by 2.0 / 2.2 cm.
class HandHeld : public HandHeldSequence {};

TEST_P(HandHeld, EveryFrameTrackedWithoutJumps) {
  REQUIRE_RAWLOG(rawlog, sequence());
  // The camera's timing is part of its calibration, like its intrinsics.
  const SlamRun r =
      checkHandHeld(trajectory(), kinect(), rawlog, test::scratchDir("Slam_" + sequence()),
                    "[tracker]\nrolling_shutter_ms = 20\ndepth_time_offset_ms = 5\n");
  // The readout learned on from the calibration stays the camera's (with a fixed, wide velocity
  // prior the scan drifted to 33 ms: the velocity followed the map's errors). On the shake the
  // motion between frames, which the readout is learned against, overshoots the hand's
  // reversals: it learns about 16 ms.
  const double readout = r.value("camera_rolling_shutter_ms");
  if (trajectory() == "shake")
    EXPECT_NEAR(readout, 18, 4) << r.result.output;
  else if (trajectory() == "scan20s")  // 22.1 / 23.7 ms measured: 20 s is not yet a lap
    EXPECT_NEAR(readout, 22, 4) << r.result.output;
  else
    EXPECT_NEAR(readout, 20, 2) << r.result.output;
}

// A hand-held camera that stays in one spot and turns (the first 16 s of "dwell", Kinect-like
// depth): every frame tracked within 2 cm, and its second half adds few keyframes: a local map
// that follows the space covered adds next to none there (issue 45).
TEST(SlamdunkRawlog, DwellingInOneSpotTracksEveryFrame) {
  REQUIRE_RAWLOG(rawlog, "handheld_dwell16s_kinect");
  const std::string dir = test::scratchDir("Slam_Dwell16s");
  const std::string frameLog = dir + "/frames.csv";
  const SlamRun r =
      runSlam(rawlog, dir,
              configWith(dir, "[tracker]\nrolling_shutter_ms = 20\ndepth_time_offset_ms = 5\n") +
                  " --frame-log " + q(frameLog));
  expectEveryFrameTracked(r, 480, 0.02);
  const auto keyframes = test::csvColumn(frameLog, "keyframes");
  ASSERT_EQ(keyframes.size(), 480u);
  std::printf("dwell, first 16 s: %s keyframes after 8 s, %s after 16 s, ATE %.4f m\n",
              keyframes[239].c_str(), keyframes[479].c_str(), r.value("ate_rmse_m"));
  // The first 8 s cover the views (10 keyframes at 2026-12-07); the next 8 s turn through views
  // they showed: a few keyframes at most where the turns reach further (none at 2026-12-07),
  // not one every few frames as a map that follows the time would.
  EXPECT_LE(std::stoi(keyframes[479]) - std::stoi(keyframes[239]), 3) << r.result.output;
}

// Keyframes culled as redundant (issue 45) leave the map, not the trajectory: every frame keeps
// its pose through the culled keyframe's successor, the keyframe trajectory lists the map's
// keyframes, and two runs are the same.
TEST(SlamdunkRawlog, CulledKeyframesLeaveTheTrajectoryWholeAndRunsRepeatable) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f");
  // With the paper's spawning rule, which makes keyframes that others already show.
  const std::string ini =
      "[tracker]\nkeyframe_cull_share = 0.6\nkeyframe_cull_observers = 2\n"
      "keyframe_covered_view = 0\n";
  std::vector<SlamRun> runs;
  for (const std::string name : {"Slam_Culling_a", "Slam_Culling_b"}) {
    const std::string dir = test::scratchDir(name);
    runs.push_back(runSlam(rawlog, dir, configWith(dir, ini)));
  }
  const SlamRun& r = runs[0];
  expectEveryFrameTracked(r, 394, 0.0095);  // 0.0073 m with every keyframe kept
  EXPECT_GE(r.value("keyframes_culled"), 1) << r.result.output;
  EXPECT_EQ(readTumTrajectory(r.trajectory).size(), 394u);
  const auto keyframes = readTumTrajectory(keyframeTrajectoryPathFor(r.trajectory));
  EXPECT_EQ(double(keyframes.size()), r.value("keyframes")) << r.result.output;
  EXPECT_EQ(test::readFile(r.trajectory), test::readFile(runs[1].trajectory));
}

/// The default INI with the depth camera 5 ms after the colour one (the synthetic camera's).
std::string defaultIniWithDepthOffset() {
  std::string ini = test::readFile(test::sourceDir() + "/config-ini/slamdunk-default.ini");
  ini = std::regex_replace(ini, std::regex("\ndepth_time_offset_ms *= *0 "),
                           "\ndepth_time_offset_ms = 5 ");
  EXPECT_NE(ini.find("depth_time_offset_ms = 5 "), std::string::npos);
  return ini;
}

// The default INI, which learns the readout from nothing (rolling_shutter_ms = 0): the frames
// tracked before it is learned (two on the shake) are registered again once it is. Without
// that, the shake's first frame pairs erred by 2.0-2.35 cm / 0.7 deg (the benchmark's table);
// with it, its first pairs 6.4 mm at most, and every pair at most 1.2 cm / 0.23 deg over
// three texture seeds.
class HandHeldLearningTiming : public HandHeldSequence {};

TEST_P(HandHeldLearningTiming, EveryFrameTrackedWithoutJumps) {
  REQUIRE_RAWLOG(rawlog, sequence());
  const SlamRun r = checkHandHeld(trajectory(), kinect(), rawlog,
                                  test::scratchDir("SlamLearningTiming_" + sequence()),
                                  defaultIniWithDepthOffset());
  EXPECT_NEAR(r.value("camera_rolling_shutter_ms"), 18, 4) << r.result.output;
}

INSTANTIATE_TEST_SUITE_P(Synthetic, HandHeldLearningTiming,
                         ::testing::Combine(::testing::Values("rotations", "shake"),
                                            ::testing::Bool()),
                         handHeldTestName);

// The default INI learns the readout from nothing (rolling_shutter_ms = 0). On the slow scan
// it came out at 42 ms for this 20 ms camera while each frame's velocity had a fixed prior as
// wide as a real Kinect's jitter needs (the velocity followed the errors of the map, keyframes
// kept them, and the readout learned against the map followed), and the ATE was 7.3 mm instead of
// 3.2. The prior's width now follows the motion model's measured error.
// The whole 2.5-minute scan is scripts/test-long.sh's (2 GB of test data); CI runs its first
// 20 s (handheld_scan20s).
void expectScanLearnsItsCamerasReadout(const std::string& name, double readoutMs,
                                       double readoutTolerance, double maxAte) {
  REQUIRE_RAWLOG(rawlog, name);
  const std::string dir = test::scratchDir("Slam_ScanLearnsReadout_" + name);
  const SlamRun r = runSlam(rawlog, dir, configWith(dir, defaultIniWithDepthOffset()));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("lost"), 0) << r.result.output;
  const double readout = r.value("camera_rolling_shutter_ms");
  std::printf("%s, readout learned from 0: %.2f ms, ATE %.4f m\n", name.c_str(), readout,
              r.value("ate_rmse_m"));
  EXPECT_NEAR(readout, readoutMs, readoutTolerance) << r.result.output;
  EXPECT_LT(r.value("ate_rmse_m"), maxAte) << r.result.output;
}

TEST(SlamdunkRawlog, HandHeldScanLearnsItsCamerasReadout) {
  expectScanLearnsItsCamerasReadout("handheld_scan", 20, 2, 0.005);
}

// In its first 20 s the readout learned from 0 is on its way to the camera's 20 ms: 14.0 ms
// measured, ATE 1.8 mm.
TEST(SlamdunkRawlog, HandHeldScan20sLearnsItsCamerasReadout) {
  expectScanLearnsItsCamerasReadout("handheld_scan20s", 15, 5, 0.004);
}

INSTANTIATE_TEST_SUITE_P(Synthetic, HandHeld,
                         ::testing::Combine(::testing::Values("rotations", "shake", "scan20s",
                                                              "scan"),
                                            ::testing::Bool()),
                         handHeldTestName);

TEST(SlamdunkRawlogBadInput, RawlogWithoutRangeScans) {
  const std::string dir = test::scratchDir("SlamBad_NoScans");
  {
    mrpt::io::CFileGZOutputStream f(dir + "/odo.rawlog");
    auto a = mrpt::serialization::archiveFrom(f);
    for (int i = 0; i < 3; ++i) a << mrpt::obs::CObservationOdometry();
  }
  const SlamRun r = runSlam(dir + "/odo.rawlog", dir, "", false);
  EXPECT_TRUE(test::failedNaming(r.result, "no CObservation3DRangeScan"));
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkRawlogBadInput, MisspelledIniKeyKeepsExistingOutput) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamBad_Ini");
  std::ofstream(dir + "/bad.ini") << "[tracker]\nratio_treshold = 0.7\n";
  std::ofstream(dir + "/trajectory.txt") << "precious\n";
  const SlamRun r = runSlam(rawlog, dir, "--config " + q(dir + "/bad.ini"));
  EXPECT_TRUE(test::failedNaming(r.result, "ratio_treshold"));
  EXPECT_EQ(readFile(dir + "/trajectory.txt"), "precious\n");
}

// A trajectory written over the ground truth or the input rawlog would lose the user's file: the
// run is refused before it starts, naming both, and both files stay as they were.
TEST(SlamdunkRawlogBadInput, OutputsOverInputsAreRefused) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamBad_Clash");
  const std::string gt = dir + "/gt.txt";
  fs::copy_file(test::groundTruthOf(rawlog), gt);
  const std::string gtBefore = readFile(gt);
  const auto run = [&](const std::string& args) {
    return test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " -q " + args);
  };
  test::CommandResult r = run("--trajectory " + q(gt) + " --gt " + q(dir + "/./gt.txt"));
  EXPECT_TRUE(test::failedNaming(r, "--trajectory '" + gt + "' is the input --gt"));
  EXPECT_EQ(readFile(gt), gtBefore);

  r = run("--trajectory " + q(dir + "/t.txt") + " --keyframes " + q(gt) + " --gt " + q(gt));
  EXPECT_TRUE(test::failedNaming(r, "--keyframes"));
  EXPECT_EQ(readFile(gt), gtBefore);
  EXPECT_FALSE(fs::exists(dir + "/t.txt"));

  // The default keyframe file ("OUT_keyframes.txt" beside OUT.txt) counts too.
  fs::copy_file(gt, dir + "/x_keyframes.txt");
  r = run("--trajectory " + q(dir + "/x.txt") + " --gt " + q(dir + "/x_keyframes.txt"));
  EXPECT_TRUE(test::failedNaming(r, "the keyframe trajectory"));
  EXPECT_EQ(readFile(dir + "/x_keyframes.txt"), gtBefore);

  // Two outputs naming one file: one would replace the other.
  r = run("--trajectory " + q(dir + "/y.txt") + " --save-map " + q(dir + "/m.map") + " --render " +
          q(dir + "/m.map"));
  EXPECT_TRUE(test::failedNaming(r, "--save-map and --render name the same file"));
}

TEST(SlamdunkRawlogBadInput, MissingRawlogAndBadGroundTruth) {
  const std::string dir = test::scratchDir("SlamBad_Missing");
  SlamRun r = runSlam(dir + "/nope.rawlog", dir, "", false);
  EXPECT_TRUE(test::failedNaming(r.result, "nope.rawlog"));

  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  std::ofstream(dir + "/gt.txt") << "1.0 0 0 0 0 0 0 1\n2.0 0 0 nan 0 0 0 1\n";
  r = runSlam(rawlog, dir, "--gt " + q(dir + "/gt.txt"), false);
  EXPECT_TRUE(test::failedNaming(r.result, "gt.txt:2"));
}

TEST(SlamdunkRawlogBadInput, TruncatedRawlogKeepsTheFramesBeforeTheDamage) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamBad_Truncated");
  test::writeEditedRawlog(src, dir + "/full.rawlog", 40, [](size_t, auto&) {});
  const auto size = fs::file_size(dir + "/full.rawlog");
  {
    std::ifstream in(dir + "/full.rawlog", std::ios::binary);
    std::string bytes(size / 2, '\0');
    in.read(bytes.data(), bytes.size());
    std::ofstream(dir + "/cut.rawlog", std::ios::binary).write(bytes.data(), bytes.size());
  }
  const SlamRun r = runSlam(dir + "/cut.rawlog", dir, "", false);
  EXPECT_EQ(r.result.exitCode, 2) << r.result.output;
  EXPECT_NE(r.result.output.find("truncated"), std::string::npos) << r.result.output;
  const Trajectory t = readTumTrajectory(r.trajectory);
  EXPECT_GT(t.size(), 10u);
  EXPECT_LT(t.size(), 40u);
}

// ------------------------------------------------------------------ threads

// Tracking and local optimization in two threads (live use): as accurate as in one.
// Run once under ThreadSanitizer too (cmake -DSLAMDUNK_TSAN=ON).
namespace {
std::string optimizerThread(const std::string& dir) {
  return configWith(dir, "[slam]\noptimizer_thread = true\n");
}
}  // namespace

// Which frames are tracked before and after each optimization depends on the threads' timing:
// measured (7 runs, the machine busy) ATE 1.0-1.6 mm, 29 optimizations, none lost.
TEST(SlamdunkRawlogThreads, OptimizerThreadKeepsTheAccuracyBoundsOnTheSyntheticLoop) {
  REQUIRE_RAWLOG(loop, "synthetic_loop");
  const std::string dir = test::scratchDir("SlamThreads");
  const SlamRun r = runSlam(loop, dir, optimizerThread(dir));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  std::printf("synthetic loop, optimizer thread: ATE %.4f m, %g optimizations, %g lost\n",
              r.value("ate_rmse_m"), r.value("optimizations"), r.value("lost"));
  EXPECT_EQ(r.value("lost"), 0) << r.result.output;
  EXPECT_LT(r.value("ate_rmse_m"), 0.003) << r.result.output;
  EXPECT_GE(r.value("optimizations"), 15) << r.result.output;
}

// Measured 0.0345-0.0375 m over 4 runs (the offline default: 0.0341 m).
TEST(SlamdunkRawlogThreads, OptimizerThreadKeepsTheAccuracyBoundsOnSevenScenes) {
  REQUIRE_RAWLOG(real, "7scenes");
  const std::string dir = test::scratchDir("SlamThreads7");
  const SlamRun s = runSlam(real, dir, optimizerThread(dir));
  ASSERT_EQ(s.result.exitCode, 0) << s.result.output;
  std::printf("7-Scenes, optimizer thread: %g of 1000 tracked, ATE %.4f m\n", s.value("tracked"),
              s.value("ate_rmse_m"));
  EXPECT_EQ(s.value("tracked"), 1000) << s.result.output;
  EXPECT_LE(s.value("ate_rmse_m"), 0.045) << s.result.output;
}

// ------------------------------------------------------------------ saved maps

namespace {

/// RMSE of the estimated positions against ground truth expressed in the frame of the first
/// ground-truth pose (= the saved map's world), without any alignment.
double rmseInMapFrame(const Trajectory& est, const Trajectory& gt, double* maxError = nullptr) {
  const Pose origin = gt.front().pose.inverse();
  double sq = 0, mx = 0;
  size_t n = 0;
  for (const auto& e : est) {
    const auto it = std::min_element(gt.begin(), gt.end(), [&](const auto& a, const auto& b) {
      return std::abs(a.timestamp - e.timestamp) < std::abs(b.timestamp - e.timestamp);
    });
    if (std::abs(it->timestamp - e.timestamp) > 0.02) continue;
    const double d = ((origin * it->pose).translation() - e.pose.translation()).norm();
    sq += d * d;
    mx = std::max(mx, d);
    ++n;
  }
  if (maxError) *maxError = mx;
  return n ? std::sqrt(sq / n) : std::nan("");
}

/// Runs the `half` frames after the first `half` from the map `first` saved of those: the
/// camera must relocalize within its first 10 frames, track all of them, and keep its
/// trajectory in the saved map's frame within `maxRmse` of the ground truth (no alignment: the
/// first half's own error counts).
void expectSecondHalfRelocalizedInTheSavedMap(const std::string& rawlog, const SlamRun& first,
                                              const std::string& dir, int half, double maxRmse) {
  ASSERT_EQ(first.result.exitCode, 0) << first.result.output;
  ASSERT_TRUE(fs::exists(first.map));
  const SlamRun r =
      runSlam(rawlog, dir, "--first-frame " + std::to_string(half) + " --load-map " + q(first.map));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  double maxInMap = 0;
  const double rmseInMap = rmseInMapFrame(
      readTumTrajectory(r.trajectory), readTumTrajectory(test::groundTruthOf(rawlog)), &maxInMap);
  const double firstTracked = r.value("first_tracked_frame");
  std::cout << rawlog << ": relocalized at frame " << firstTracked << " of the second half, "
            << r.value("tracked") << " tracked, RMSE in the saved map's frame " << rmseInMap
            << " m (max " << maxInMap << ")\n";
  EXPECT_GE(firstTracked, 0);
  EXPECT_LT(firstTracked, 10);
  EXPECT_EQ(r.value("tracked"), half);
  EXPECT_LE(rmseInMap, maxRmse);
}

/// Largest position and angle error of the keyframes of `keyframes` against the ground truth
/// (the two sessions' files together), expressed in the frame of `firstMapStart`.
std::pair<double, double> worstKeyframeErrorInMapFrame(const Trajectory& keyframes,
                                                       const Trajectory& groundTruth,
                                                       const Pose& firstMapStart) {
  double metres = 0, degrees = 0;
  for (const auto& k : keyframes) {
    const auto it = std::find_if(groundTruth.begin(), groundTruth.end(), [&](const auto& g) {
      return std::abs(g.timestamp - k.timestamp) < 1e-4;
    });
    if (it == groundTruth.end()) return {std::nan(""), std::nan("")};
    const Pose expected = firstMapStart.inverse() * it->pose;
    metres = std::max(metres, translationDistance(expected, k.pose));
    degrees = std::max(degrees, rotationDistance(expected, k.pose) * 180 / M_PI);
  }
  return {metres, degrees};
}

/// Maps `first` (with `firstExtra` arguments) and saves the map in dir/first.map, then runs
/// `second` from it (in dir/second, with `extra` arguments); both must exit 0.
std::pair<SlamRun, SlamRun> twoSessions(const std::string& first, const std::string& second,
                                        const std::string& dir, const std::string& extra = "",
                                        const std::string& firstExtra = "") {
  SlamRun a = runSlam(first, dir, firstExtra + " --save-map " + q(dir + "/first.map"));
  EXPECT_EQ(a.result.exitCode, 0) << a.result.output;
  const std::string secondDir = dir + "/second";
  fs::create_directories(secondDir);
  SlamRun b = runSlam(second, secondDir, "--load-map " + q(dir + "/first.map") + " " + extra);
  EXPECT_EQ(b.result.exitCode, 0) << b.result.output;
  return {a, b};
}

}  // namespace

// A second session starts where the first session's map does not reach: it maps on its own (a
// second component) and, once it walks into the mapped rooms, place recognition joins it to
// the loaded map. The saved map holds both, in the first map's frame.
TEST(SlamdunkRawlogMaps, ASecondSessionOutsideTheMapJoinsIt) {
  REQUIRE_RAWLOG(first, "tour_session1");
  REQUIRE_RAWLOG(second, "tour_session2");
  const std::string dir = test::scratchDir("SlamMaps_Join");
  const auto [a, b] = twoSessions(
      first, second, dir,
      "--save-map " + q(dir + "/joined.map") + " --keyframes " + q(dir + "/keyframes.txt"));
  ASSERT_EQ(b.result.exitCode, 0) << b.result.output;
  EXPECT_EQ(b.value("components_started"), 1) << b.result.output;
  EXPECT_EQ(b.value("components_joined"), 1) << b.result.output;
  EXPECT_GE(b.value("tracked"), 260) << b.result.output;  // lost only before mapping alone

  Trajectory groundTruth = readTumTrajectory(test::groundTruthOf(first));
  const Pose firstMapStart = groundTruth.front().pose;
  for (const auto& g : readTumTrajectory(test::groundTruthOf(second))) groundTruth.push_back(g);
  const Trajectory keyframes = readTumTrajectory(dir + "/keyframes.txt");
  EXPECT_GT(keyframes.size(), a.value("keyframes")) << "the second session's keyframes";
  // The map is in the first camera's frame: its first keyframe is the origin.
  EXPECT_LT(translationDistance(keyframes.front().pose, Pose::Identity()), 1e-9);
  EXPECT_LT(rotationDistance(keyframes.front().pose, Pose::Identity()), 1e-9);
  const auto [metres, degrees] =
      worstKeyframeErrorInMapFrame(keyframes, groundTruth, firstMapStart);
  std::cout << "joined map: " << keyframes.size() << " keyframes, worst " << metres << " m "
            << degrees << " deg from the ground truth in the first map's frame\n";
  EXPECT_LE(metres, 0.02);
  EXPECT_LE(degrees, 1.0);

  // The saved map is the joined one: a third run from it relocalizes at once.
  const std::string thirdDir = dir + "/third";
  fs::create_directories(thirdDir);
  const SlamRun c = runSlam(second, thirdDir, "--load-map " + q(dir + "/joined.map"));
  ASSERT_EQ(c.result.exitCode, 0) << c.result.output;
  EXPECT_EQ(c.value("components_started"), 0) << c.result.output;
  EXPECT_LE(c.value("first_tracked_frame"), 5) << c.result.output;
}

// The twin office: the first session maps the corridor from D and room A (the twin tour's
// frames 900-1099), the second starts in the corridor from B (not in the map: a second
// component) and walks into room C, A's copy (its frames 350-549). Place recognition verifies
// joins from C's keyframes into A, and refuses them: where such a join puts the corridor's
// keyframes, the map's keyframes of the other corridor see otherwise.
TEST(SlamdunkRawlogMaps, ASessionInTheTwinOfAMappedRoomIsNotJoinedToIt) {
  REQUIRE_RAWLOG(tour, "tour_twins");
  const SlamRun b = twoSessions(tour, tour, test::scratchDir("SlamMaps_TwinsJoin"),
                                "--first-frame 350 --max-frames 200", "--first-frame 900")
                        .second;
  EXPECT_EQ(b.value("frames"), 200) << b.result.output;
  ASSERT_EQ(b.result.exitCode, 0) << b.result.output;
  EXPECT_EQ(b.value("components_started"), 1) << b.result.output;
  EXPECT_EQ(b.value("components_joined"), 0) << b.result.output;
  EXPECT_EQ(b.value("relocalizations"), 0) << b.result.output;
  EXPECT_GE(b.value("component_joins_refused"), 1) << "the twin rooms no longer tempt a join";
}

// In the map's frame the figure includes the first half's own drift (10.5 mm measured; 6.4 mm
// with the dense depth term, which exact depth favours).
TEST(SlamdunkRawlogMaps, RelocalizesTheSecondHalfOfTheSyntheticLoopInTheSavedMap) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  REQUIRE_SHARED_RUN(firstHalf, "synthetic_loop_200");
  expectSecondHalfRelocalizedInTheSavedMap(rawlog, firstHalf,
                                           test::scratchDir("SlamMaps_RelocLoop"), 200, 0.015);
}

// The figure includes the first half's own mapping error (measured 0.0550 m, max 0.0875 m, in 2
// runs; with the loaded map shifted 10 cm, 0.131 m).
TEST(SlamdunkRawlogMaps, RelocalizesTheSecondHalfOfSevenScenes) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("SlamMaps_Reloc7");
  SlamRun firstHalf =
      runSlam(rawlog, dir, "--max-frames 500 --save-map " + q(dir + "/first-half.map"));
  firstHalf.map = dir + "/first-half.map";
  const std::string second = dir + "/second";
  fs::create_directories(second);
  expectSecondHalfRelocalizedInTheSavedMap(rawlog, firstHalf, second, 500, 0.08);
}

// ------------------------------------------------------------------ localization only

namespace {

/// Replays the whole of `rawlog` in localization only (--localize, and `extra`) in the map
/// `mapping` saved, into dir: the map saved again as dir/after.map, the frame log dir/f.csv.
SlamRun localizeIn(const SlamRun& mapping, const std::string& rawlog, const std::string& dir,
                   const std::string& extra = "") {
  SlamRun localized =
      runSlam(rawlog, dir,
              "--load-map " + q(mapping.map) + " --localize --save-map " + q(dir + "/after.map") +
                  " --frame-log " + q(dir + "/f.csv") + " " + extra);
  EXPECT_EQ(localized.result.exitCode, 0) << localized.result.output;
  return localized;
}

}  // namespace

// A replay of the mapped sequence in its map: every frame tracked against the map as it was
// saved, which it leaves byte for byte as it was (no keyframe, no optimization), about as
// accurate as mapping was.
TEST(SlamdunkRawlogMaps, LocalizationOnlyTracksTheMappedSequenceWithoutChangingTheMap) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  REQUIRE_SHARED_RUN(mapping, "synthetic_loop");
  const std::string dir = test::scratchDir("SlamMaps_Localize");
  const SlamRun localized = localizeIn(mapping, rawlog, dir);
  std::cout << "mapping: ATE " << mapping.value("ate_rmse_m") << " m, "
            << mapping.value("keyframes") << " keyframes; localization only: ATE "
            << localized.value("ate_rmse_m") << " m, " << localized.value("frames_outside_map")
            << " frames outside the map\n";
  EXPECT_EQ(localized.value("tracked"), 400) << localized.result.output;
  EXPECT_EQ(localized.value("keyframes"), 0);
  EXPECT_EQ(localized.value("optimizations"), 0);
  EXPECT_EQ(readFile(dir + "/after.map"), readFile(mapping.map));
  EXPECT_LE(localized.value("ate_rmse_m"), 1.1 * mapping.value("ate_rmse_m"));
  EXPECT_EQ(localized.value("frames_outside_map"), 0) << "the map covers every view it was made of";
}

// A second lap round the mapped loop, at another pace (330 frames for the first lap's 400:
// other poses and images of the same room): tracked in the first lap's map without adding to
// it, as accurately as mapping that lap on its own.
TEST(SlamdunkRawlogMaps, LocalizationOnlyTracksASecondLapInTheFirstLapsMap) {
  REQUIRE_RAWLOG(firstLap, "synthetic_loop");
  REQUIRE_RAWLOG(secondLap, "synthetic_loop_lap2");
  REQUIRE_SHARED_RUN(firstLapMapped, "synthetic_loop");
  const std::string dir = test::scratchDir("SlamMaps_LocalizeLap");
  const std::string alone = dir + "/alone", localized = dir + "/localized";
  fs::create_directories(alone);
  fs::create_directories(localized);
  const SlamRun mapping = runSlam(secondLap, alone);
  const SlamRun r = runSlam(secondLap, localized,
                            "--load-map " + q(firstLapMapped.map) + " --localize --save-map " +
                                q(localized + "/after.map"));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  std::cout << "second lap: mapped on its own ATE " << mapping.value("ate_rmse_m") << " m ("
            << mapping.value("keyframes") << " keyframes); localized in the first lap's map ATE "
            << r.value("ate_rmse_m") << " m, " << r.value("frames_outside_map")
            << " frames outside the map\n";
  EXPECT_EQ(r.value("tracked"), 330) << r.result.output;
  EXPECT_EQ(r.value("keyframes"), 0);
  EXPECT_EQ(readFile(localized + "/after.map"), readFile(firstLapMapped.map));
  EXPECT_LE(r.value("ate_rmse_m"), 1.1 * mapping.value("ate_rmse_m"));
}

// A map of the loop's first half: the second half's views are not in it. They are reported
// outside the map or lost, nothing is added, and the camera is found again where the loop
// returns to the mapped half.
TEST(SlamdunkRawlogMaps, LocalizationOnlySaysWhenTheCameraLeavesTheMap) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  REQUIRE_SHARED_RUN(mapping, "synthetic_loop_200");
  const std::string dir = test::scratchDir("SlamMaps_LocalizeHalf");
  const SlamRun localized = localizeIn(mapping, rawlog, dir);
  EXPECT_EQ(localized.value("frames"), 400);
  EXPECT_EQ(localized.value("keyframes"), 0);
  EXPECT_EQ(readFile(dir + "/after.map"), readFile(mapping.map));
  const auto outside = test::csvColumn(dir + "/f.csv", "outside_map");
  const auto status = test::csvColumn(dir + "/f.csv", "status");
  ASSERT_EQ(outside.size(), 400u);
  size_t firstHalfOutside = 0, secondHalfAway = 0;
  for (size_t i = 0; i < 400; ++i) {
    const bool away = outside[i] == "1" || status[i] == "lost";
    (i < 200 ? firstHalfOutside : secondHalfAway) += away;
  }
  EXPECT_LE(firstHalfOutside, 5u) << "the mapped half is in the map";
  EXPECT_GE(secondHalfAway, 100u) << "the unmapped half is not";
  EXPECT_GE(localized.value("frames_outside_map"), 20) << localized.result.output;
  EXPECT_GE(localized.value("relocalizations"), 1) << "found again back in the mapped half";
  EXPECT_LE(localized.value("ate_rmse_m"), 0.01) << "its tracked frames are where they were";

  const SlamRun noMap = runSlam(rawlog, dir, "--localize");
  EXPECT_NE(noMap.result.exitCode, 0);
  EXPECT_NE(noMap.result.output.find("--load-map"), std::string::npos) << noMap.result.output;
}

// The same half map extended (--extend-map): the unmapped half gets keyframes of its own,
// every frame is tracked, and the loaded keyframes stay exactly where they were.
TEST(SlamdunkRawlogMaps, LocalizationOnlyExtendedMapsTheRestAndKeepsTheLoadedKeyframes) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  REQUIRE_SHARED_RUN(mapping, "synthetic_loop_200");
  const std::string dir = test::scratchDir("SlamMaps_LocalizeExtend");
  const SlamRun extended = localizeIn(mapping, rawlog, dir, "--extend-map");
  EXPECT_EQ(extended.value("tracked"), 400) << extended.result.output;
  EXPECT_GE(extended.value("keyframes"), 5);
  EXPECT_LE(extended.value("ate_rmse_m"), 0.005) << extended.result.output;
  const auto newKeyframe = test::csvColumn(dir + "/f.csv", "new_keyframe");
  for (size_t i = 0; i < 200 && i < newKeyframe.size(); ++i)
    EXPECT_EQ(newKeyframe[i], "0") << "a keyframe in the mapped half, frame " << i;
  // The loaded keyframes' poses, as the map held them and as the extended map holds them.
  const auto loaded = test::tumPoseLines(keyframeTrajectoryPathFor(mapping.trajectory));
  const auto after = test::tumPoseLines(keyframeTrajectoryPathFor(extended.trajectory));
  ASSERT_GT(after.size(), loaded.size());
  EXPECT_TRUE(std::equal(loaded.begin(), loaded.end(), after.begin()));

  const SlamRun alone = runSlam(rawlog, dir, "--extend-map");
  EXPECT_NE(alone.result.exitCode, 0);
  EXPECT_NE(alone.result.output.find("--localize"), std::string::npos) << alone.result.output;
}

TEST(SlamdunkRawlogMaps, WritesMapDenseOutputsPictureAndSimpleMap) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamMaps_Outputs");
  const SlamRun r =
      runSlam(rawlog, dir,
              "--save-map " + q(dir + "/m.map") + " --dense " + q(dir + "/dense") + " --render " +
                  q(dir + "/m.png") + " --simplemap " + q(dir + "/m.simplemap"));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  for (const char* f : {"m.map", "dense.ply", "dense.pcd", "dense.ot", "dense.bt", "m.png",
                        "m.3Dscene", "m.simplemap"})
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  // The saved map renders through the stand-alone renderer too.
  const auto render = test::runCommand(test::toolPath("slamdunk-render") + " " + q(dir + "/m.map") +
                                       " " + q(dir + "/again.png") + " --width 320 --height 240");
  EXPECT_EQ(render.exitCode, 0) << render.output;
  const cv::Mat png = cv::imread(dir + "/again.png");
  EXPECT_EQ(png.cols, 320);
  EXPECT_EQ(png.rows, 240);
}

TEST(SlamdunkRawlogMaps, CorruptMapIsAClearError) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("SlamMaps_Corrupt");
  std::ofstream(dir + "/bad.map") << "definitely not a map";
  const SlamRun r = runSlam(rawlog, dir, "--load-map " + q(dir + "/bad.map"));
  EXPECT_TRUE(test::failedNaming(r.result, "bad.map"));
}
