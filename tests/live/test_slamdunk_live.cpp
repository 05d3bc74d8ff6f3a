// slamdunk-live end to end, with the replay source standing in for a camera: real-time replay
// (dropped frames, accuracy against the offline app on the same data), Ctrl-C midway, OpenNI2
// with no camera attached, the generic-sensor path (CCameraSensor), recording, bad input.

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/live/CheckpointWriter.h>
#ifdef SLAMDUNK_LIVE_TEST_MAPS
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#endif

#include "ChildProcess.h"
#include "EditedRawlog.h"
#include "TestData.h"

#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

std::string writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A live INI replaying `rawlog` (or no rawlog: given with --rawlog), extra lines appended to
/// the [slamdunk-live] section.
std::string replayIni(const std::string& dir, const std::string& rawlog,
                      const std::string& liveExtra = "", const std::string& replayExtra = "") {
  return writeFile(dir + "/live.ini", "[slamdunk-live]\nsource = REPLAY\n" + liveExtra +
                                          "\n[REPLAY]\ndriver = replay\nrawlog = " + rawlog + "\n" +
                                          replayExtra + "\n");
}

struct LiveRun {
  test::CommandResult result;
  std::string trajectory, map;
  double seconds = 0;
  double value(const std::string& key) const { return test::jsonValue(result.output, key); }
};

LiveRun runLive(const std::string& ini, const std::string& outDir, const std::string& extra = "") {
  LiveRun r;
  r.trajectory = outDir + "/trajectory.txt";
  r.map = outDir + "/run.map";
  const auto t0 = std::chrono::steady_clock::now();
  r.result = test::runCommand(test::toolPath("slamdunk-live") + " --config " + q(ini) +
                              " --trajectory " + q(r.trajectory) + " --json -q " + extra);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

/// The real-time replays' stretch of 7-Scenes: its first 10 s.
constexpr int kReplayFrames = 300;
constexpr double kRecordingFps = 30;

}  // namespace

// ------------------------------------------------------------------ real-time replay

TEST(SlamdunkLive, RealTimeReplayDropsNothingAndMatchesTheOfflineAccuracy) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("Live_7Scenes_1x");
  const std::string gt = test::groundTruthOf(rawlog);

  // What the pipeline does at 30 Hz shows from the first seconds: the offline app's run on
  // them is the suite's shared one (shared_run_7scenes_300).
  constexpr int kFrames = kReplayFrames;
  const std::string firstFrames = " --max-frames " + std::to_string(kFrames);
  REQUIRE_SHARED_RUN_DIR(offlineRun, "7scenes_300");
  const test::CommandResult offline{0, test::readFile(offlineRun + "/output.txt")};
  const double offlineAte = test::jsonValue(offline.output, "ate_rmse_m");

  const LiveRun live = runLive(replayIni(dir, rawlog), dir, "--gt " + q(gt) + firstFrames);
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  const double liveAte = live.value("ate_rmse_m");
  std::printf(
      "7scenes at 1x, first %d frames: received %g, dropped %g, processed %g at %.1f frames/s, "
      "ATE %.4f m (offline %.4f m), optimizations %g; longest gap between frames %.1f ms, "
      "longest wait for the tracker %.1f ms\n",
      kFrames, live.value("frames_received"), live.value("frames_dropped"),
      live.value("frames_processed"), live.value("fps_processed"), liveAte, offlineAte,
      live.value("optimizations"), live.value("source_gap_ms_max"),
      live.value("queue_wait_ms_max"));
  EXPECT_EQ(live.value("frames_received"), kFrames) << live.result.output;
  // Paced by the timestamps: 300 frames at 30 Hz take 10 s, not the offline app's ~3 s.
  EXPECT_NEAR(live.value("active_s"), kFrames / kRecordingFps, 1.5) << live.result.output;
  // On its own thread the optimizer is busy for part of the session, well below all of it.
  EXPECT_GT(live.value("optimizer_share"), 0.0) << live.result.output;
  EXPECT_LT(live.value("optimizer_share"), 0.8) << live.result.output;
  EXPECT_EQ(readTumTrajectory(live.trajectory).size(), live.value("tracked"));
#ifdef SLAMDUNK_SANITIZED
  // Sanitized code cannot keep up with 30 Hz: frames are dropped, so neither "no drops" nor
  // "the offline accuracy" holds. The Release suite checks both; here the session must only
  // account for every frame.
  std::printf("sanitizer build: real-time assertions (no drops, offline ATE) skipped\n");
  EXPECT_EQ(live.value("frames_processed") + live.value("frames_dropped"), kFrames)
      << live.result.output;
#else
  // No drop, unless the machine starved the whole process: then the replay thread itself,
  // which only sleeps and reads, was late by more than three frame periods (a shared CI machine
  // did that once, a 105 ms gap and 1 frame dropped), and at most 2 frames may go. A pipeline
  // that falls behind on its own drops with the source on time, and fails here.
  const double dropped = live.value("frames_dropped");
  const bool sourceStarved = live.value("source_gap_ms_max") > 3 * 1000.0 / 30;
  if (dropped > 0 && sourceStarved)
    std::printf("the process was starved (the source was %.0f ms late): %g frame(s) dropped\n",
                live.value("source_gap_ms_max"), dropped);
  EXPECT_LE(dropped, sourceStarved ? 2 : 0) << live.result.output;
  EXPECT_EQ(live.value("frames_processed") + dropped, kFrames) << live.result.output;
  // Live, the optimizer runs beside tracking, so which frames are tracked before and after
  // each optimization changes from run to run: on the whole recording 12 runs at 1x gave
  // 0.0347-0.0380 m against the offline 0.0341 m (median +6 %, at most +11 %), about the spread
  // the offline run shows over RANSAC seeds alone (0.0335-0.0368 m over seeds 42-51); on its
  // first 600 frames 4 runs gave 0.0304-0.0307 m against the offline 0.0292 m (+4 to +5 %), on
  // its first 300 3 runs 0.0295 m against 0.0281 m (+5 %).
  EXPECT_LE(std::abs(liveAte - offlineAte), 0.15 * offlineAte)
      << "live " << liveAte << " m vs offline " << offlineAte << " m\n"
      << live.result.output << offline.output;
#endif
}

TEST(SlamdunkLive, TripleSpeedReplayCompletesWithAValidTrajectory) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("Live_7Scenes_3x");
  // The 1x test's frames, sent at 90 frames/s.
  constexpr int kFrames = kReplayFrames;
  constexpr double kSpeed = 3, kSentFps = kSpeed * kRecordingFps;
  const LiveRun live =
      runLive(replayIni(dir, rawlog), dir,
              "--speed " + std::to_string(int(kSpeed)) + " --max-frames " +
                  std::to_string(kFrames) + " --gt " + q(test::groundTruthOf(rawlog)));
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  std::printf(
      "7scenes at 3x, first %d frames: received %g, dropped %g, processed %g at %.1f frames/s, "
      "lost %g, ATE %.4f m\n",
      kFrames, live.value("frames_received"), live.value("frames_dropped"),
      live.value("frames_processed"), live.value("fps_processed"), live.value("lost"),
      live.value("ate_rmse_m"));
  EXPECT_EQ(live.value("frames_received"), kFrames) << live.result.output;
  EXPECT_EQ(live.value("frames_processed") + live.value("frames_dropped"), kFrames)
      << live.result.output;
  const Trajectory traj = readTumTrajectory(live.trajectory);
  EXPECT_GT(traj.size(), 100u);
  EXPECT_EQ(traj.size(), live.value("tracked"));
#ifdef SLAMDUNK_SANITIZED
  // Sanitized code tracks at 7-9 frames/s: most of the 90 frames/s are dropped (see the 1x
  // test); the Release suite checks drops and accuracy.
  std::printf("sanitizer build: drops and ATE not checked\n");
#else
  // 90 frames/s asks for most of what this machine's tracker gives (110-120 frames/s median
  // over these frames, slower on the frames with more features), so how many frames drop
  // follows the machine's speed: 1-23 of 300 measured on the idle machine (3 runs). What the
  // pipeline must do whatever the machine: process frames as fast as its tracker can, up to the
  // 90 frames/s sent; measured 91-98 % of that (the test runs alone in CI, RUN_SERIAL). At
  // 120 frames/s it was 75-83 % (over 600 frames): the optimizer's thread takes its share. A 50 ms
  // stall before each frame's tracking, a deliberate break, gave 26 % (at 60 frames/s). None lost
  // in any run; ATE 0.0293-0.0303 m (offline over the same frames: 0.0281 m).
  const double trackerFps = 1000.0 / live.value("ms_tracking_median");
  const double expectedFps = std::min(kSentFps, trackerFps);
  std::printf("tracker alone: %.1f frames/s (median); processed %.0f %% of min(%.0f, that)\n",
              trackerFps, 100 * live.value("fps_processed") / expectedFps, kSentFps);
  EXPECT_GE(live.value("fps_processed"), 0.75 * expectedFps)
      << "frames dropped that the tracker had time for:\n"
      << live.result.output;
  EXPECT_EQ(live.value("lost"), 0) << live.result.output;
  EXPECT_LE(live.value("ate_rmse_m"), 0.05) << live.result.output;
#endif
}

// Keyframes culled on the tracking thread while the optimizer's thread works on the graph and
// checkpoints write it: the optimizer leaves culled keyframes out, every tracked frame keeps a
// pose, the final map loads.
TEST(SlamdunkLive, CullingBesideTheOptimizerThreadAndCheckpoints) {
  REQUIRE_RAWLOG(rawlog, "fr1_xyz_400f");
  const std::string dir = test::scratchDir("Live_Culling");
  const std::string ini = replayIni(dir, rawlog,
                                    "checkpoint_every_keyframes = 2\n"
                                    "[pipeline.tracker]\nkeyframe_cull_share = 0.6\n"
                                    "keyframe_cull_observers = 2\n"
                                    "keyframe_covered_view = 0\n");  // the paper's spawning
  const LiveRun live =
      runLive(ini, dir,
              "--speed 2 --map " + q(dir + "/run.map") + " --gt " + q(test::groundTruthOf(rawlog)));
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  EXPECT_EQ(readTumTrajectory(live.trajectory).size(), live.value("tracked"));
  EXPECT_EQ(live.value("lost"), 0) << live.result.output;
#ifndef SLAMDUNK_SANITIZED  // sanitized code drops most frames: few keyframes to cull
  EXPECT_GE(live.value("keyframes_culled"), 1) << live.result.output;
  EXPECT_LE(live.value("ate_rmse_m"), 0.012) << live.result.output;
#endif
  const std::string reload = test::scratchDir("Live_Culling_reload");
  const LiveRun again = runLive(replayIni(reload, rawlog), reload,
                                "--speed 4 --max-frames 30 --load-map " + q(dir + "/run.map"));
  EXPECT_EQ(again.result.exitCode, 0) << again.result.output;
  EXPECT_EQ(again.value("lost"), 0) << again.result.output;
}

// Soak tests replay a recording again and again ([REPLAY] loops): each lap's timestamps follow
// the last lap's by one frame interval, so time keeps increasing as from a camera, and the
// trajectory stays a valid TUM file.
TEST(SlamdunkLive, ReplayLoopsKeepTheTimestampsIncreasing) {
  REQUIRE_RAWLOG(src, "synthetic_sweep");
  const std::string dir = test::scratchDir("Live_Loops");
  const std::string rawlog = dir + "/short.rawlog";
  test::writeEditedRawlog(src, rawlog, 20, [](size_t, auto&) {});
  const std::string frames = dir + "/frames.csv";
  const LiveRun r = runLive(replayIni(dir, rawlog, "queue_capacity = 100", "loops = 3"), dir,
                            "--speed 3 --frame-log " + q(frames));
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_EQ(r.value("frames_received"), 60) << r.result.output;
  EXPECT_EQ(r.value("frames_processed"), 60) << r.result.output;
  EXPECT_EQ(r.value("frames_out_of_order"), 0) << r.result.output;
  std::vector<double> stamps;
  {
    std::ifstream in(frames);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) stamps.push_back(std::stod(line.substr(line.find(',') + 1)));
  }
  ASSERT_EQ(stamps.size(), 60u);
  for (size_t i = 1; i < stamps.size(); ++i) EXPECT_GT(stamps[i], stamps[i - 1]) << "frame " << i;
  EXPECT_NEAR(stamps[20] - stamps[19], 1 / 30.0, 1e-4);  // the next lap, one interval later
  EXPECT_NEAR(stamps[40] - stamps[20], 20 / 30.0, 1e-4);
  const Trajectory traj = readTumTrajectory(r.trajectory);
  EXPECT_EQ(traj.size(), r.value("tracked"));

  // 0 = until stopped (here by --max-frames); a negative count is an error naming the key.
  const LiveRun endless = runLive(replayIni(dir, rawlog, "queue_capacity = 100", "loops = 0"), dir,
                                  "--speed 3 --max-frames 45");
  ASSERT_EQ(endless.result.exitCode, 0) << endless.result.output;
  EXPECT_EQ(endless.value("frames_received"), 45) << endless.result.output;
  const LiveRun bad = runLive(replayIni(dir, rawlog, "", "loops = -1"), dir);
  EXPECT_TRUE(test::failedNaming(bad.result, "loops must be >= 0"));
}

// ------------------------------------------------------------------ interrupt

namespace {
/// Polls the checkpoint folder of a running app until its checkpoint holds at least `tracked`
/// tracked frames in at least `sequence` checkpoints; nullopt if the app exits first or 120 s
/// pass (a deadline far beyond the few seconds of replay it takes): the test fails then.
/// `seen`, if given, gets each checkpoint seen, in order.
std::optional<live::CheckpointInfo> waitForCheckpoint(
    test::ChildProcess& app, const std::string& folder, size_t tracked, size_t sequence = 1,
    std::vector<live::CheckpointInfo>* seen = nullptr) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (app.alive() && std::chrono::steady_clock::now() < end) {
    try {
      const live::CheckpointInfo info = live::CheckpointInfo::read(folder);
      if (seen && (seen->empty() || seen->back().sequence != info.sequence)) seen->push_back(info);
      if (info.framesTracked >= tracked && info.sequence >= sequence) return info;
    } catch (const std::runtime_error&) {
      // none yet
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return std::nullopt;
}

/// Wall-clock time, seconds since 1970 (as checkpoint.txt's unix_time).
double unixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The frames a run interrupted midway has tracked at least: ~3.3 s at 30 Hz (the sanitizers'
// tracking runs at 7-9 frames/s). Once a checkpoint holds more, the run is midway.
#ifdef SLAMDUNK_SANITIZED
constexpr size_t kFewestFrames = 20;
#else
constexpr size_t kFewestFrames = 100;
#endif

/// Starts the app on a 1x replay with a checkpoint every second, sends `signal` once a
/// checkpoint holds kFewestFrames tracked frames (proof that the run is midway, however slow
/// the machine), and waits for the app's exit (up to 120 s); r.seconds: from the signal to the
/// exit. Fails the test when the run never gets there.
LiveRun interruptedRun(const std::string& rawlog, const std::string& dir, int signal) {
  LiveRun r;
  r.trajectory = dir + "/trajectory.txt";
  r.map = dir + "/run.map";
  r.seconds = std::numeric_limits<double>::infinity();
  const std::string log = dir + "/output.txt";
  test::ChildProcess app({test::toolPath("slamdunk-live"), "--config",
                          replayIni(dir, rawlog, "checkpoint_every_seconds = 1"), "--trajectory",
                          r.trajectory, "--map", r.map, "--gridmap", dir + "/grid", "--json"},
                         {}, log);
  EXPECT_TRUE(app.started());
  const auto midway = waitForCheckpoint(app, dir + "/trajectory_checkpoint", kFewestFrames);
  EXPECT_TRUE(midway) << "no checkpoint with " << kFewestFrames
                      << " tracked frames before the app ended or 120 s passed; output:\n"
                      << readText(log);
  if (midway) {
    const auto signalled = std::chrono::steady_clock::now();
    kill(app.pid(), signal);
    r.result.exitCode = app.wait(120);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
  }
  r.result.output = readText(log);
  return r;
}

void expectCompleteOutputs(const LiveRun& r) {
  // Documented: an interrupt is the normal end of a live session, exit code 0.
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  EXPECT_NE(r.result.output.find("\"interrupted\": true"), std::string::npos) << r.result.output;
  const Trajectory traj = readTumTrajectory(r.trajectory);
  std::printf("interrupted: %zu frames tracked, %g keyframes, stopped %.2f s after the signal\n",
              traj.size(), r.value("keyframes"), r.seconds);
  // Signalled once a checkpoint held kFewestFrames: at least those, and well under the 1000
  // of the recording (checkpoints come every second).
  EXPECT_GE(traj.size(), kFewestFrames) << r.result.output;
  EXPECT_LT(traj.size(), 300u) << r.result.output;
  EXPECT_EQ(traj.size(), r.value("tracked"));
  const fs::path kf = fs::path(r.trajectory).parent_path() / "trajectory_keyframes.txt";
  EXPECT_EQ(readTumTrajectory(kf.string()).size(), r.value("keyframes"));
  EXPECT_LT(r.seconds, 30) << "the app took too long to stop after the signal";
#ifdef SLAMDUNK_LIVE_TEST_MAPS
  const auto map = CKeyframeGraphMap::loadFromFile(r.map);
  ASSERT_TRUE(map && map->graph());
  EXPECT_EQ(map->graph()->keyframeCount(), r.value("keyframes"));
#endif
  const fs::path grid = fs::path(r.trajectory).parent_path() / "grid.gridmap";
  EXPECT_GT(readGridMap(grid.string()).getSizeX(), 10u);
}
}  // namespace

TEST(SlamdunkLive, SigintMidwayWritesEveryOutput) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  expectCompleteOutputs(interruptedRun(rawlog, test::scratchDir("Live_Sigint"), SIGINT));
}

TEST(SlamdunkLive, SigtermMidwayWritesEveryOutput) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  expectCompleteOutputs(interruptedRun(rawlog, test::scratchDir("Live_Sigterm"), SIGTERM));
}

// ------------------------------------------------------------------ crash safety

namespace {
/// The timestamps of a rawlog's frames, in order.
std::vector<double> frameTimestamps(const std::string& rawlog) {
  RawlogReader reader(rawlog);
  std::vector<double> stamps;
  while (auto obs = reader.next()) stamps.push_back(mrpt::Clock::toDouble(obs->timestamp));
  return stamps;
}

/// The largest "checkpoint N written in X ms" of a status log, in seconds.
double slowestCheckpointSeconds(const std::string& log) {
  double slowest = 0;
  const std::regex re("checkpoint [0-9]+ written in ([0-9.]+) ms");
  for (auto it = std::sregex_iterator(log.begin(), log.end(), re); it != std::sregex_iterator();
       ++it)
    slowest = std::max(slowest, std::stod((*it)[1]) / 1000);
  return slowest;
}
}  // namespace

TEST(SlamdunkLive, SigkillMidwayLosesAtMostOneCheckpointInterval) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("Live_Sigkill");
  const double interval = 2.0;  // seconds between checkpoints (time only, for a sharp bound)
  const std::string ini =
      replayIni(dir, rawlog, "checkpoint_every_seconds = 2\ncheckpoint_every_keyframes = 0\n");
  const std::string log = dir + "/output.txt";
  const std::string folder = dir + "/run_checkpoint";
  test::ChildProcess app(
      {test::toolPath("slamdunk-live"), "--config", ini, "--trajectory", dir + "/run.txt"}, {},
      log);
  ASSERT_TRUE(app.started());
#ifdef SLAMDUNK_SANITIZED
  const size_t fewestFrames = 30;  // tracking runs at 7-9 frames/s under the sanitizers
#else
  const size_t fewestFrames = 100;  // about 3.3 s of 30 Hz frames
#endif
  // SIGKILL 1.3 s after the 4th checkpoint (holding at least fewestFrames tracked frames) was
  // taken: between two checkpoints, as 9.3 s into the replay was on an idle machine, however
  // slow this one is. No handler runs, nothing is flushed; only what the checkpoints put on
  // disk survives. The time of the kill is taken just before it.
  std::vector<live::CheckpointInfo> seen;
  const auto fourth = waitForCheckpoint(app, folder, fewestFrames, 4, &seen);
  ASSERT_TRUE(fourth) << "no 4th checkpoint with " << fewestFrames
                      << " tracked frames before the app ended or 120 s passed; output:\n"
                      << readText(log);
  const double killAt = fourth->unixTime + 1.3;
  if (unixNow() < killAt)
    std::this_thread::sleep_for(std::chrono::duration<double>(killAt - unixNow()));
  const double killTime = unixNow();
  kill(app.pid(), SIGKILL);
  const int exitCode = app.wait(120);
  const std::string stderrText = readText(log);
  EXPECT_EQ(exitCode, 128 + 9) << "the app was not killed:\n" << stderrText;
  EXPECT_FALSE(fs::exists(dir + "/run.txt")) << "the final outputs cannot exist after SIGKILL";

  // The checkpoint loads, its parts agree, and it is recent.
  const live::CheckpointInfo info = live::CheckpointInfo::read(folder);
  const double lostSeconds = killTime - info.unixTime;
  const double slowest = slowestCheckpointSeconds(stderrText);
  std::printf(
      "SIGKILL: checkpoint %zu taken %.2f s before the kill (interval %.1f s, slowest write "
      "%.2f s): %zu frames, %zu keyframes\n",
      info.sequence, lostSeconds, interval, slowest, info.framesProcessed, info.keyframes);
  EXPECT_GE(info.sequence, 4u) << stderrText;
  EXPECT_GE(lostSeconds, 0);
  // Taken every interval: the kill's moment follows the 4th checkpoint, however late it comes,
  // so the checkpoints' own times show whether they came on time (measured: every 2.0 s).
  for (size_t i = 1; i < seen.size(); ++i) {
    const double gap = seen[i].unixTime - seen[i - 1].unixTime;
    std::printf("checkpoint %zu taken %.2f s after checkpoint %zu\n", seen[i].sequence, gap,
                seen[i - 1].sequence);
    EXPECT_EQ(seen[i].sequence, seen[i - 1].sequence + 1) << "a checkpoint went unseen";
    EXPECT_LE(gap, interval + slowest + 0.5) << stderrText;
  }
  // At most one interval lost: the next checkpoint's snapshot is due `interval` after this
  // one's, and it counts once its write is complete.
  EXPECT_LE(lostSeconds, interval + slowest + 0.5) << stderrText;
#ifdef SLAMDUNK_LIVE_TEST_MAPS
  const auto map = CKeyframeGraphMap::loadFromFile(folder + "/map.map");
  EXPECT_EQ(map->graph()->keyframeCount(), info.keyframes);
  EXPECT_GE(info.keyframes, 5u);
#endif
  const Trajectory traj = readTumTrajectory(folder + "/trajectory.txt");
  ASSERT_EQ(traj.size(), info.framesTracked);
  ASSERT_GE(traj.size(), fewestFrames);
  EXPECT_NEAR(traj.back().timestamp, info.lastFrameTimestamp, 1e-6);
  // It covers the frames up to the last checkpoint: from the first frame on, in order, each a
  // frame of the recording, and every frame processed (7-Scenes loses none). Frames the replay
  // dropped while tracking was behind are not in it: a machine busy with other work drops a
  // few (2 of 235 beside two busy loops), which is SlamdunkLive.RealTimeReplay...'s concern.
  // (Trajectory files keep timestamps to the microsecond.)
  const std::vector<double> stamps = frameTimestamps(rawlog);
  EXPECT_NEAR(traj.front().timestamp, stamps.front(), 1e-6);
  size_t upToLast = 0;
  while (upToLast < stamps.size() && stamps[upToLast] <= info.lastFrameTimestamp + 1e-6) ++upToLast;
  for (size_t i = 0; i < traj.size(); ++i) {
    const auto next = std::lower_bound(stamps.begin(), stamps.end(), traj[i].timestamp - 1e-6);
    ASSERT_TRUE(next != stamps.end() && std::abs(*next - traj[i].timestamp) < 1e-6) << i;
    if (i > 0) ASSERT_GT(traj[i].timestamp, traj[i - 1].timestamp) << i;
  }
#ifndef SLAMDUNK_SANITIZED  // at 7-9 frames/s the replay drops most frames: the rest are far apart
  EXPECT_EQ(info.framesTracked, info.framesProcessed);
#endif
  EXPECT_LE(info.framesProcessed, upToLast);
  std::printf("checkpoint: %zu of the recording's first %zu frames processed\n",
              info.framesProcessed, upToLast);

  // --load-map on the checkpoint resumes mapping: the frames after it relocalize at once and
  // continue the checkpoint's trajectory in its world.
  const auto resumed =
      test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " --load-map " +
                       q(folder + "/map.map") + " --first-frame " + std::to_string(upToLast) +
                       " --max-frames 120 --trajectory " + q(dir + "/resumed.txt") + " --json -q");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  EXPECT_GE(test::jsonValue(resumed.output, "tracked"), 115) << resumed.output;
  EXPECT_GE(test::jsonValue(resumed.output, "keyframes"), 1) << resumed.output;
  const Trajectory next = readTumTrajectory(dir + "/resumed.txt");
  ASSERT_FALSE(next.empty());
  const double jump = translationDistance(next.front().pose, traj.back().pose);
  const double travelled = translationDistance(traj.front().pose, traj.back().pose);
  std::printf(
      "resumed at frame %zu: first pose %.3f m from the checkpoint's last (%.3f m from the "
      "start)\n",
      upToLast, jump, travelled);
  // Relocalization in 7-Scenes maps is good to about 5 cm (README); a new world would start
  // at the origin, which the camera has left far behind by then.
  EXPECT_GT(travelled, 0.25);
  EXPECT_LT(jump, 0.10) << "the resumed trajectory is not in the checkpoint's world";
}

TEST(SlamdunkLive, LoadMapContinuesInTheSavedMap) {
  REQUIRE_RAWLOG(rawlog, "7scenes");
  const std::string dir = test::scratchDir("Live_LoadMap");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  // A first session maps the first 150 frames; a second one replays from the start in its map.
  const LiveRun first = runLive(replayIni(dir, rawlog), dir + "/a",
                                "--speed 2 --max-frames 150 --map " + q(dir + "/a/run.map"));
  ASSERT_EQ(first.result.exitCode, 0) << first.result.output;
  // At the recording's pace: beside two busy tests (three at a time on two cores) it took 40 of
  // 90 frames sent twice as fast.
  const LiveRun second = runLive(replayIni(dir, rawlog), dir + "/b",
                                 "--speed 1 --max-frames 90 --load-map " + q(dir + "/a/run.map"));
  ASSERT_EQ(second.result.exitCode, 0) << second.result.output;
  // Every frame the tracker took (a loaded machine may drop some) is tracked in the map.
#ifdef SLAMDUNK_SANITIZED
  EXPECT_GE(second.value("frames_processed"), 8) << second.result.output;  // 7-9 frames/s
#else
  EXPECT_GE(second.value("frames_processed"), 45) << second.result.output;
#endif
  EXPECT_EQ(second.value("tracked"), second.value("frames_processed")) << second.result.output;
  const Trajectory a = readTumTrajectory(first.trajectory);
  const Trajectory b = readTumTrajectory(second.trajectory);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  // The same first frame, relocalized in the saved map: the same pose in the same world.
  EXPECT_DOUBLE_EQ(a.front().timestamp, b.front().timestamp);
  EXPECT_LT(translationDistance(a.front().pose, b.front().pose), 0.05);
  EXPECT_LT(rotationDistance(a.front().pose, b.front().pose), 0.05);
}

// A live session started where the loaded map does not reach maps on its own, and place
// recognition joins it to the loaded map once the camera walks in (on the optimizer's thread).
TEST(SlamdunkLive, ASessionOutsideTheLoadedMapJoinsIt) {
  REQUIRE_RAWLOG(first, "tour_session1");
  REQUIRE_RAWLOG(second, "tour_session2");
  const std::string dir = test::scratchDir("Live_Join");
  const auto mapped =
      test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(first) + " --trajectory " +
                       q(dir + "/first.txt") + " -q --save-map " + q(dir + "/first.map"));
  ASSERT_EQ(mapped.exitCode, 0) << mapped.output;
  const LiveRun live =
      runLive(replayIni(dir, second), dir,
              "--load-map " + q(dir + "/first.map") + " --map " + q(dir + "/run.map"));
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  EXPECT_EQ(live.value("components_started"), 1) << live.result.output;
#ifndef SLAMDUNK_SANITIZED  // sanitized code drops most frames: too few keyframes to agree
  EXPECT_EQ(live.value("components_joined"), 1) << live.result.output;
  // The saved map is the joined one: the session's first frames relocalize in it at once.
  const auto again =
      test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(second) + " --trajectory " +
                       q(dir + "/again.txt") + " --json -q --load-map " + q(dir + "/run.map"));
  ASSERT_EQ(again.exitCode, 0) << again.output;
  EXPECT_EQ(test::jsonValue(again.output, "components_started"), 0) << again.output;
  EXPECT_LE(test::jsonValue(again.output, "first_tracked_frame"), 5) << again.output;
#endif
}

// ------------------------------------------------------------------ other sources

TEST(SlamdunkLive, OpenNI2WithoutACameraFailsFastAndClearly) {
  // This machine has no RGB-D camera: the shipped OpenNI2 INI must fail quickly, say what was
  // looked for, and not crash (MRPT's driver aborts or throws from its destructor otherwise).
  const std::string dir = test::scratchDir("Live_NoCamera");
  // Untimed first start: loading ~400 shared libraries from a cold disk cache took 7 s on this
  // machine, which is not what "fails fast" is about.
  test::runCommand(test::toolPath("slamdunk-live") + " --help");
  const LiveRun r = runLive(test::sourceDir() + "/config-ini/live-openni2.ini", dir);
  EXPECT_NE(r.result.exitCode, 0) << r.result.output;
  EXPECT_LT(r.result.exitCode, 128) << "crashed: " << r.result.output;
  EXPECT_NE(r.result.output.find("OpenNI2"), std::string::npos) << r.result.output;
  EXPECT_NE(r.result.output.find("device_number = 0"), std::string::npos) << r.result.output;
  EXPECT_NE(r.result.output.find("lsusb"), std::string::npos) << r.result.output;
  EXPECT_LT(r.seconds, 10) << r.result.output;
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkLive, GenericSensorCCameraSensorReplaysARawlog) {
  REQUIRE_RAWLOG(rawlog, "fr1_desk_9f");
  const std::string dir = test::scratchDir("Live_CCameraSensor");
  const std::string ini = writeFile(dir + "/camera.ini",
                                    "[slamdunk-live]\nsource = CAM\n[CAM]\ndriver = CCameraSensor\n"
                                    "grabber_type = rawlog\nrawlog_file = " +
                                        rawlog + "\nprocess_rate = 30\nsensorLabel = CAM\n");
  const LiveRun r = runLive(ini, dir);
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  std::printf("CCameraSensor at 30 Hz: received %g, dropped %g, processed %g, tracked %g\n",
              r.value("frames_received"), r.value("frames_dropped"), r.value("frames_processed"),
              r.value("tracked"));
  EXPECT_EQ(r.value("frames_received"), 9) << r.result.output;
  EXPECT_EQ(r.value("frames_processed") + r.value("frames_dropped"), 9) << r.result.output;
  EXPECT_EQ(readTumTrajectory(r.trajectory).size(), r.value("tracked")) << r.result.output;
#ifdef SLAMDUNK_SANITIZED
  // Tracking runs at 7-9 frames/s, about 4 times slower than 30 Hz: frames are dropped, and
  // fr1/desk moves fast between those left.
  EXPECT_GE(r.value("tracked"), 5) << r.result.output;
#else
  // Measured (3 runs, beside two busy loops on this machine's two cores): all 9 processed and
  // tracked. The queue holds 4 frames (133 ms) for a slow moment: one may be dropped.
  EXPECT_GE(r.value("frames_processed"), 8) << r.result.output;
  EXPECT_EQ(r.value("tracked"), r.value("frames_processed")) << r.result.output;
#endif
}

// A camera driver stamps a frame when it has arrived; sensor_stamp_latency_ms moves every stamp
// back to the exposure's middle, as tum2rawlog's camera files do for recorded sequences.
TEST(SlamdunkLive, SensorStampLatencyMovesEveryStampBack) {
  REQUIRE_RAWLOG(rawlog, "fr1_desk_9f");
  const std::string dir = test::scratchDir("Live_StampLatency");
  const std::string ini = writeFile(dir + "/camera.ini",
                                    "[slamdunk-live]\nsource = CAM\nsensor_stamp_latency_ms = 12\n"
                                    "[CAM]\ndriver = CCameraSensor\ngrabber_type = rawlog\n"
                                    "rawlog_file = " +
                                        rawlog + "\nprocess_rate = 30\nsensorLabel = CAM\n");
  const LiveRun r = runLive(ini, dir);
  ASSERT_EQ(r.result.exitCode, 0) << r.result.output;
  const Trajectory poses = readTumTrajectory(r.trajectory);
  ASSERT_GE(poses.size(), 5u) << r.result.output;
  const std::vector<double> source = frameTimestamps(rawlog);
  for (const auto& p : poses) {
    // Each pose is of one source frame, 12 ms before that frame's stamp (the trajectory file
    // keeps microseconds).
    const auto frame = std::find_if(source.begin(), source.end(), [&](double s) {
      return std::abs(s - 0.012 - p.timestamp) < 2e-6;
    });
    EXPECT_NE(frame, source.end()) << "pose at " << p.timestamp << " is no source stamp - 12 ms";
  }
}

TEST(SlamdunkLive, RecordingReplaysWithoutTheSourceImages) {
  REQUIRE_RAWLOG(rawlog, "7scenes");  // images stored externally: the recording must embed them
  const std::string dir = test::scratchDir("Live_Record");
  const std::string recording = dir + "/recorded.rawlog";
  const LiveRun live =
      runLive(replayIni(dir, rawlog), dir, "--max-frames 60 --record " + q(recording));
  ASSERT_EQ(live.result.exitCode, 0) << live.result.output;
  EXPECT_EQ(live.value("recorded"), 60) << live.result.output;
  EXPECT_FALSE(fs::exists(dir + "/recorded_Images"));
  const auto offline = test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(recording) +
                                        " --trajectory " + q(dir + "/offline.txt") + " --json -q");
  ASSERT_EQ(offline.exitCode, 0) << offline.output;
  EXPECT_EQ(test::jsonValue(offline.output, "frames"), 60) << offline.output;
  EXPECT_EQ(test::jsonValue(offline.output, "lost"), 0) << offline.output;
}

// ------------------------------------------------------------------ bad input

TEST(SlamdunkLiveBadInput, MissingIni) {
  const std::string dir = test::scratchDir("Live_MissingIni");
  const LiveRun r = runLive(dir + "/nope.ini", dir);
  EXPECT_TRUE(test::failedNaming(r.result, "nope.ini' does not exist"));
}

TEST(SlamdunkLiveBadInput, UnknownKeysAreNamed) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Live_UnknownKey");
  LiveRun r = runLive(replayIni(dir, rawlog, "queue_capacty = 3"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "queue_capacty"));

  r = runLive(replayIni(dir, rawlog, "", "sped = 2"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "sped"));

  r = runLive(replayIni(dir, rawlog, "\n[pipeline.slam]\noptimiser_thread = true"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "optimiser_thread"));
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkLiveBadInput, MissingReplayRawlog) {
  const std::string dir = test::scratchDir("Live_MissingRawlog");
  LiveRun r = runLive(replayIni(dir, dir + "/missing.rawlog"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "missing.rawlog' does not exist"));

  r = runLive(replayIni(dir, ""), dir);  // no rawlog anywhere
  EXPECT_TRUE(test::failedNaming(r.result, "--rawlog"));

  r = runLive(replayIni(dir, ""), dir, "--rawlog " + q(dir + "/other.rawlog"));
  EXPECT_TRUE(test::failedNaming(r.result, "other.rawlog' does not exist"));
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkLiveBadInput, StampLatencyOutOfRangeOrOnAReplay) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Live_BadLatency");
  LiveRun r = runLive(replayIni(dir, rawlog, "sensor_stamp_latency_ms = 250"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "sensor_stamp_latency_ms must be within +-100 ms"));
  // A rawlog's stamps are the exposure's already: correcting them again is refused.
  r = runLive(replayIni(dir, rawlog, "sensor_stamp_latency_ms = 12"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "driver = replay"));
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkLiveBadInput, OutputsOverInputsAreRefused) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Live_Clash");
  const std::string ini = replayIni(dir, rawlog);
  const std::string iniBefore = readText(ini);
  LiveRun r = runLive(ini, dir, "--map " + q(ini));
  EXPECT_TRUE(test::failedNaming(r.result, "--map '" + ini + "' is the input --config"));
  EXPECT_EQ(readText(ini), iniBefore);
  EXPECT_FALSE(fs::exists(r.trajectory));
}

TEST(SlamdunkLiveBadInput, BadSourceSections) {
  const std::string dir = test::scratchDir("Live_BadSource");
  LiveRun r = runLive(writeFile(dir + "/a.ini", "[slamdunk-live]\nsource = NOPE\n"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "[NOPE]"));

  r = runLive(writeFile(dir + "/b.ini", "[slamdunk-live]\nsource = S\n[S]\ndriver = CNoSuchCam\n"),
              dir);
  EXPECT_TRUE(test::failedNaming(r.result, "CNoSuchCam"));

  r = runLive(test::sourceDir() + "/config-ini/live-openni2.ini", dir, "--speed 2");
  EXPECT_TRUE(test::failedNaming(r.result, "replay source only"));

  r = runLive(replayIni(dir, "x.rawlog", "", "read_ahead_frames = 0"), dir);
  EXPECT_TRUE(test::failedNaming(r.result, "read_ahead_frames must be >= 1"));
}
