// Checkpoints of a live session: written every N keyframes or S seconds while frames are
// tracked, complete and consistent (map, trajectory, keyframes and their description agree),
// replaced atomically, and a map that resumes mapping. (The SIGKILL test of the app is in
// test_slamdunk_live.cpp.)

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/grid_map/GridMapFiles.h>
#include <slamdunk/live/CheckpointWriter.h>
#include <slamdunk/live/LiveSlam.h>
#include <slamdunk/live/PushFrameSource.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>

#include "TestData.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

namespace fs = std::filesystem;
using namespace slamdunk;
using namespace slamdunk::live;

namespace {

std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> readFrames(const std::string& rawlog) {
  RawlogReader reader(rawlog);
  std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
  while (auto obs = reader.next()) {
    obs->load();
    frames.push_back(obs);
  }
  return frames;
}

/// Pushes the frames one at a time (each tracked before the next comes: no drops), sleeping
/// `pauseMs` after each.
LiveResult runSession(LiveSlam& live, PushFrameSource& push,
                      const std::vector<mrpt::obs::CObservation3DRangeScan::Ptr>& frames,
                      double pauseMs = 0) {
  live.start();
  for (size_t i = 0; i < frames.size(); ++i) {
    push.push(frames[i]);
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (live.counters().processed < i + 1 && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (pauseMs > 0)
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(pauseMs));
  }
  push.close();
  while (!live.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return live.finish();
}

/// Entries a failed or interrupted swap would leave beside the checkpoint folder.
std::vector<std::string> leftovers(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos)
      found.push_back(e.path().string());
  return found;
}

}  // namespace

TEST(Checkpoints, EveryFewKeyframesACompleteCheckpointThatResumesMapping) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("Checkpoints_Keyframes");
  const auto frames = readFrames(rawlog);
  ASSERT_EQ(frames.size(), 400u);

  LiveOptions options;
  options.checkpoint.everyKeyframes = 4;
  options.checkpoint.everySeconds = 0;
  LiveSession session;
  session.trajectory = dir + "/run.txt";
  auto source = std::make_unique<PushFrameSource>();
  PushFrameSource& push = *source;
  LiveSlam live(options, std::move(source), session);
  EXPECT_EQ(live.checkpointFolder(), dir + "/run_checkpoint");
  // The session ends halfway round the loop (as a crash would), the rest is resumed below.
  const size_t sessionFrames = 220;
  const LiveResult result = runSession(
      live, push, {frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(sessionFrames)});
  ASSERT_TRUE(result.checkpoints);
  const CheckpointFigures& cp = *result.checkpoints;
  EXPECT_TRUE(cp.error.empty()) << cp.error;
  std::printf(
      "%zu keyframes, %zu checkpoints: median %.1f ms, graph copy max %.2f ms\n",
      result.stats.keyframes, cp.written,
      cp.totalMs.empty() ? 0.0 : cp.totalMs[cp.totalMs.size() / 2],
      cp.snapshotMs.empty() ? 0.0 : *std::max_element(cp.snapshotMs.begin(), cp.snapshotMs.end()));
  // One per 4 new keyframes (the writer may merge two when it is still busy with one).
  EXPECT_GE(cp.written, result.stats.keyframes / 4 / 2);
  EXPECT_LE(cp.written, result.stats.keyframes / 4);

  // The last checkpoint is complete and its parts agree with each other.
  const std::string folder = dir + "/run_checkpoint";
  const CheckpointInfo info = CheckpointInfo::read(folder);
  EXPECT_EQ(info.sequence, cp.written);
  EXPECT_GE(info.keyframes, 4u);
  EXPECT_LE(info.keyframes, result.stats.keyframes);
  const auto map = CKeyframeGraphMap::loadFromFile(folder + "/map.map");
  EXPECT_EQ(map->graph()->keyframeCount(), info.keyframes);
  const Trajectory traj = readTumTrajectory(folder + "/trajectory.txt");
  ASSERT_EQ(traj.size(), info.framesTracked);
  EXPECT_EQ(info.framesTracked, info.framesProcessed) << "the exact loop loses no frame";
  EXPECT_LE(info.framesProcessed, sessionFrames);
  // It covers every frame up to the last one it names, in order.
  // (Trajectory files keep timestamps to the microsecond.)
  for (size_t i = 0; i < traj.size(); ++i)
    ASSERT_NEAR(traj[i].timestamp, mrpt::Clock::toDouble(frames[i]->timestamp), 1e-6) << i;
  EXPECT_NEAR(traj.back().timestamp, info.lastFrameTimestamp, 1e-6);
  EXPECT_EQ(readTumTrajectory(folder + "/keyframes.txt").size(), info.keyframes);
  EXPECT_TRUE(leftovers(dir).empty()) << leftovers(dir).front();

  // Resuming: the rest of the sequence, on the checkpoint's map, relocalizes at its first frame
  // and keeps mapping.
  SlamSystem resumed(LiveOptions::liveSlamDefaults(), map->graph());
  size_t tracked = 0, firstTracked = frames.size();
  for (size_t i = info.framesProcessed; i < frames.size(); ++i) {
    const TrackingResult r = resumed.process(*frames[i]);
    if (r.status == TrackingStatus::Lost) continue;
    ++tracked;
    firstTracked = std::min(firstTracked, i);
  }
  resumed.finish();
  const size_t rest = frames.size() - info.framesProcessed;
  std::printf("resumed at frame %zu: %zu of %zu frames tracked, keyframes %zu -> %zu\n",
              info.framesProcessed, tracked, rest, info.keyframes,
              resumed.graph()->keyframeCount());
  EXPECT_LE(firstTracked, info.framesProcessed + 2);
  EXPECT_GE(tracked, rest - 3);
  EXPECT_GT(resumed.graph()->keyframeCount(), info.keyframes);
}

TEST(Checkpoints, EverySecondsAndReplacedInPlace) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Checkpoints_Seconds");
  auto frames = readFrames(rawlog);
  frames.resize(60);
  LiveOptions options;
  options.checkpoint.everyKeyframes = 0;
  options.checkpoint.everySeconds = 0.4;
  options.checkpoint.folder = dir + "/cp";
  auto source = std::make_unique<PushFrameSource>();
  PushFrameSource& push = *source;
  LiveSlam live(options, std::move(source));  // no trajectory output: the folder is given
  const LiveResult result = runSession(live, push, frames, 30);  // about 2 s of frames
  ASSERT_TRUE(result.checkpoints);
  EXPECT_TRUE(result.checkpoints->error.empty()) << result.checkpoints->error;
  EXPECT_GE(result.checkpoints->written, 3u);
  const CheckpointInfo info = CheckpointInfo::read(dir + "/cp");
  EXPECT_EQ(info.sequence, result.checkpoints->written);
  EXPECT_GT(info.framesProcessed, 30u);
  EXPECT_EQ(readTumTrajectory(dir + "/cp/trajectory.txt").size(), info.framesTracked);
  EXPECT_TRUE(leftovers(dir).empty()) << leftovers(dir).front();
}

// A session asked for the occupancy grid writes it at the end, and each checkpoint holds the
// grid of its own map: what the library makes of the checkpoint's map.map, cell for cell.
TEST(Checkpoints, HoldTheOccupancyGridOfTheirMap) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("Checkpoints_GridMap");
  auto frames = readFrames(rawlog);
  frames.resize(150);
  LiveOptions options;
  options.checkpoint.everyKeyframes = 4;
  options.checkpoint.everySeconds = 0;
  LiveSession session;
  session.trajectory = dir + "/run.txt";
  session.gridMap = dir + "/grid";
  auto source = std::make_unique<PushFrameSource>();
  PushFrameSource& push = *source;
  LiveSlam live(options, std::move(source), session);
  const LiveResult result = runSession(live, push, frames);
  ASSERT_TRUE(result.checkpoints);
  EXPECT_TRUE(result.checkpoints->error.empty()) << result.checkpoints->error;
  EXPECT_TRUE(result.outputFailures.empty()) << result.outputFailures.front();

  const std::string folder = dir + "/run_checkpoint";
  const CheckpointInfo info = CheckpointInfo::read(folder);
  ASSERT_EQ(info.gridMap, "gridmap.gridmap");
  const auto map = CKeyframeGraphMap::loadFromFile(folder + "/map.map");
  const GridMap expected = GridMapBuilder(options.slam.gridMap).build(*map->graph());
  EXPECT_EQ(readGridMap(folder + "/gridmap.gridmap").getRawMap(), expected.grid.getRawMap());
  EXPECT_GT(expected.occupiedCells, 100u);
  for (const char* ext : {".png", ".yaml"}) EXPECT_TRUE(fs::exists(folder + "/gridmap" + ext));

  const GridMap last = GridMapBuilder(options.slam.gridMap).build(*result.graph);
  EXPECT_EQ(readGridMap(dir + "/grid.gridmap").getRawMap(), last.grid.getRawMap());
  for (const char* ext : {".png", ".yaml"}) EXPECT_TRUE(fs::exists(dir + "/grid" + ext));
}

TEST(Checkpoints, AKilledSessionsTemporaryFolderIsRemovedAtTheNextStart) {
  const std::string dir = test::scratchDir("Checkpoints_Abandoned");
  // A process that is gone (this test's own child), and one that is running (this test).
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  waitpid(child, nullptr, 0);
  const std::string abandoned = dir + "/.cp.tmp-" + std::to_string(child) + "-3";
  const std::string running = dir + "/.cp.tmp-" + std::to_string(getpid()) + "-9";
  const std::string other = dir + "/.other.tmp-" + std::to_string(child) + "-1";
  for (const auto& d : {abandoned, running, other}) fs::create_directories(d + "/inside");
  LiveOptions options;
  options.checkpoint.folder = dir + "/cp/";  // a trailing slash names the same folder
  LiveSlam live(options, std::make_unique<PushFrameSource>());
  EXPECT_EQ(live.checkpointFolder(), dir + "/cp/");
  EXPECT_FALSE(fs::exists(abandoned));
  EXPECT_TRUE(fs::exists(running)) << "a live process's temporary folder is left alone";
  EXPECT_TRUE(fs::exists(other)) << "only this checkpoint folder's temporaries are removed";
}

TEST(Checkpoints, NoPlaceNoCheckpoints) {
  // Checkpoints on (the default) but neither a folder nor a trajectory to put one beside.
  LiveSlam live(LiveOptions{}, std::make_unique<PushFrameSource>());
  EXPECT_EQ(live.checkpointFolder(), "");
  EXPECT_FALSE(live.checkpointFigures());
}

TEST(Checkpoints, FolderWhoseParentIsMissingIsRefused) {
  const std::string dir = test::scratchDir("Checkpoints_BadFolder");
  LiveOptions options;
  options.checkpoint.folder = dir + "/no/such/cp";
  try {
    LiveSlam live(options, std::make_unique<PushFrameSource>());
    FAIL() << "a checkpoint folder that cannot be made must be refused before starting";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no/such' does not exist"), std::string::npos) << e.what();
  }
}

TEST(Checkpoints, InfoFileErrorsNameTheFileAndKey) {
  const std::string dir = test::scratchDir("Checkpoints_Info");
  try {
    CheckpointInfo::read(dir);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/checkpoint.txt' does not exist"),
              std::string::npos)
        << e.what();
  }
  std::ofstream(dir + "/checkpoint.txt") << "sequence = 2\nframes_processed = 12x\n";
  try {
    CheckpointInfo::read(dir);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'frames_processed' is not a number: 12x"),
              std::string::npos)
        << e.what();
  }
}
