// The live viewer's parts without a window: pause and step (PlaybackControl), what the scene
// shows for a real run (LiveMapScene rendered offscreen: map cloud, keyframe frustums, loop
// closure, trajectory, current camera, image with inliers and rejected matches), and the error
// when there is no display; and, under Xvfb, that closing the window waits for MRPT's window
// thread. The window itself is tested through the apps under Xvfb (test_gui_apps.cpp).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/slam/SlamSystem.h>
#include <slamdunk/viewer/LiveMapScene.h>
#include <slamdunk/viewer/LiveViewer.h>
#include <slamdunk/viewer/PlaybackControl.h>

#include "TestData.h"
#include "VirtualDisplay.h"

#include <gtest/gtest.h>
#include <mrpt/gui/CDisplayWindow3D.h>
#include <mrpt/img/CImage.h>
#include <mrpt/opengl/CFBORender.h>
#include <opencv2/imgcodecs.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

using namespace slamdunk;
using namespace slamdunk::viewer;
using namespace std::chrono_literals;

// ------------------------------------------------------------------ pause and step

namespace {
/// Runs waitForTurn() on another thread; true if it returned within `wait`.
bool turnWithin(PlaybackControl& control, std::chrono::milliseconds wait) {
  std::atomic<bool> done{false};
  std::thread t([&] {
    control.waitForTurn();
    done = true;
  });
  const auto end = std::chrono::steady_clock::now() + wait;
  while (!done && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(1ms);
  const bool returned = done;
  if (!returned) control.release();  // let the thread go
  t.join();
  return returned;
}
}  // namespace

TEST(PlaybackControl, RunsUntilPausedThenStepsOneFrameAtATime) {
  PlaybackControl c;
  EXPECT_TRUE(turnWithin(c, 1000ms)) << "not paused: no waiting";
  c.togglePause();
  EXPECT_TRUE(c.paused());
  EXPECT_FALSE(turnWithin(c, 200ms)) << "paused: the next frame waits";
}

TEST(PlaybackControl, StepLetsExactlyOneFrameThrough) {
  PlaybackControl c;
  c.togglePause();
  c.step();
  EXPECT_TRUE(turnWithin(c, 1000ms));
  EXPECT_TRUE(c.paused()) << "still paused after the step";
  EXPECT_FALSE(turnWithin(c, 200ms)) << "one step, one frame";
  c.step();
  c.step();
  EXPECT_TRUE(turnWithin(c, 1000ms));
  EXPECT_TRUE(turnWithin(c, 1000ms));
}

TEST(PlaybackControl, StepWhileRunningPausesAfterOneFrame) {
  PlaybackControl c;
  c.step();
  EXPECT_TRUE(c.paused());
  EXPECT_TRUE(turnWithin(c, 1000ms));
  EXPECT_FALSE(turnWithin(c, 200ms));
}

TEST(PlaybackControl, ResumeAndReleaseNeverWaitAgain) {
  PlaybackControl c;
  c.togglePause();
  c.togglePause();
  EXPECT_FALSE(c.paused());
  EXPECT_TRUE(turnWithin(c, 1000ms));
  c.togglePause();
  c.release();  // the window was closed while paused: the run must not hang
  EXPECT_TRUE(turnWithin(c, 1000ms));
  EXPECT_TRUE(turnWithin(c, 1000ms));
}

// ------------------------------------------------------------------ the scene, offscreen

namespace {
cv::Vec3b bgr(const unsigned char (&c)[3]) { return cv::Vec3b(c[2], c[1], c[0]); }

/// What the viewer is handed during a run, kept to build scenes from afterwards.
struct RunForViewer {
  std::shared_ptr<KeyframeGraph> graph;
  std::vector<FrameRecord> frames;
  std::vector<std::pair<KeyframeId, cv::Mat>> colours;
  std::vector<KeyframeId> loops;
  ViewerFrame latest;
  ViewerStatus status;
};

RunForViewer runSynthetic(const std::string& rawlog) {
  RunForViewer run;
  SlamSystem slam{SlamOptions()};
  RawlogReader reader(rawlog);
  while (auto obs = reader.next()) {
    obs->load();
    const TrackingResult r = slam.process(*obs);
    run.frames.push_back({r.timestamp, r.status, r.reference, r.poseInReference});
    const cv::Mat colour = obs->intensityImage.asCvMatRef();
    if (r.newKeyframe) run.colours.emplace_back(r.keyframeId, colour);
    if (r.loopClosure) run.loops.push_back(r.keyframeId);
    run.latest = ViewerFrame{run.frames.size() - 1, r.timestamp,     r.status, r.pose, colour,
                             r.inlierPixels,        r.rejectedPixels};
  }
  slam.finish();
  run.graph = slam.graph();
  run.status.frames = run.frames.size();
  run.status.keyframes = run.graph->keyframeCount();
  run.status.loopClosures = run.loops.size();
  return run;
}

/// The scene of a run rendered offscreen at 1024x640, from above the loop's centre (empty
/// when this machine has no offscreen OpenGL).
cv::Mat render(const RunForViewer& run, bool cloud, bool markLoops, const std::string& png) {
  LiveMapSceneOptions options;
  options.showCloud = cloud;
  LiveMapScene scene(options);
  for (const auto& f : run.frames) scene.addFrame(f);
  for (const auto& [id, image] : run.colours) scene.setKeyframeColour(id, image);
  if (markLoops)
    for (KeyframeId id : run.loops) scene.markLoopClosure(id);
  mrpt::opengl::COpenGLScene gl;
  scene.attachTo(gl);
  scene.update(*run.graph, &run.latest, run.status);
  auto& camera = gl.getViewport("main")->getCamera();
  camera.setPointingAt(0, 0, 0);
  camera.setZoomDistance(9);
  camera.setElevationDegrees(75);
  camera.setAzimuthDegrees(200);
  mrpt::img::CImage image;
  try {
    mrpt::opengl::CFBORender fbo(1024, 640);
    fbo.setCamera(gl, camera);
    fbo.render_RGB(gl, image);
  } catch (const std::exception& e) {
    std::printf("no offscreen OpenGL: %s\n", e.what());
    return {};
  }
  cv::Mat shot = image.asCvMatRef().clone();
  cv::imwrite(png, shot);
  return shot;
}

// The image in the top-left corner: 30 % of the width, 4:3.
const cv::Rect kInset(0, 0, int(0.3 * 1024), int(0.3 * 1024 * 3 / 4));

struct Seen {
  int frustums = 0, camera = 0, loopEdges = 0, coloured = 0, inliers = 0;
};
Seen seen(const cv::Mat& shot) {
  Seen s;
  cv::Mat map = shot.clone();
  map(kInset).setTo(cv::Scalar(0, 0, 0));
  s.frustums = test::pixelsNear(map, bgr(LiveMapScene::kFrustum), 30);
  s.camera = test::pixelsNear(map, bgr(LiveMapScene::kCamera), 30);
  s.loopEdges = test::pixelsNear(map, bgr(LiveMapScene::kLoopEdge), 30);
  s.coloured = test::colouredPixels(map, 0, 180);
  s.inliers = test::pixelsNear(shot(kInset), bgr(LiveMapScene::kInlier), 60);
  return s;
}
}  // namespace

TEST(LiveMapScene, ShowsTheMapCameraLoopClosureAndFeaturesOfARealRun) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("LiveMapScene_Loop");
  const RunForViewer run = runSynthetic(rawlog);  // the synthetic loop closes once
  ASSERT_GE(run.loops.size(), 1u);
  ASSERT_GT(run.latest.inliers.size(), 50u) << "the tracker reports its inliers' pixels";

  // Without the cloud, every colour below can only come from the object drawn in it.
  const cv::Mat objects = render(run, false, true, dir + "/objects.png");
  if (objects.empty()) GTEST_SKIP() << "no offscreen OpenGL (EGL) here";
  const cv::Mat unmarked = render(run, false, false, dir + "/no_loop_mark.png");
  const cv::Mat full = render(run, true, true, dir + "/scene.png");
  const Seen a = seen(objects), b = seen(unmarked), c = seen(full);
  std::printf(
      "offscreen (%s): frustums %d, camera %d, loop edges %d (%d unmarked), inlier marks %d; "
      "coloured %d px with the cloud, %d without\n",
      dir.c_str(), a.frustums, a.camera, a.loopEdges, b.loopEdges, a.inliers, c.coloured,
      a.coloured);
  EXPECT_GE(a.frustums, 100);
  EXPECT_GE(a.camera, 20);
  EXPECT_GE(a.loopEdges, 10) << "the loop closure's edges are not highlighted";
  EXPECT_EQ(b.loopEdges, 0) << "highlighted edges without a loop closure";
  EXPECT_GE(a.inliers, 50) << "no inlier marks on the camera image";
  EXPECT_GE(c.coloured, 1024 * 640 / 20) << "the map's cloud covers little of the view";
  EXPECT_GE(c.coloured, 3 * a.coloured);
  EXPECT_NE(LiveMapScene::statusLine(&run.latest, run.status)
                .find("keyframes " + std::to_string(run.status.keyframes)),
            std::string::npos);
}

TEST(LiveMapSceneSmall, AShortRunRendersItsKeyframesAndFeatures) {
  // The same scene code on 40 frames (kept in the sanitizer suite, which leaves out the loop).
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("LiveMapScene_Short");
  RunForViewer run;
  SlamSystem slam{SlamOptions()};
  RawlogReader reader(rawlog);
  for (size_t i = 0; i < 40; ++i) {
    auto obs = reader.next();
    ASSERT_TRUE(obs);
    obs->load();
    const TrackingResult r = slam.process(*obs);
    run.frames.push_back({r.timestamp, r.status, r.reference, r.poseInReference});
    if (r.newKeyframe) run.colours.emplace_back(r.keyframeId, obs->intensityImage.asCvMatRef());
    run.latest = ViewerFrame{i,
                             r.timestamp,
                             r.status,
                             r.pose,
                             obs->intensityImage.asCvMatRef(),
                             r.inlierPixels,
                             r.rejectedPixels};
  }
  run.graph = slam.graph();
  const cv::Mat shot = render(run, true, true, dir + "/scene.png");
  if (shot.empty()) GTEST_SKIP() << "no offscreen OpenGL (EGL) here";
  const Seen s = seen(shot);
  std::printf("40 frames (%s/scene.png): frustums %d, camera %d, coloured %d, inlier marks %d\n",
              dir.c_str(), s.frustums, s.camera, s.coloured, s.inliers);
  EXPECT_GE(s.camera, 10);
  EXPECT_GE(s.coloured, 1000);
  EXPECT_GE(s.inliers, 20);
}

// ------------------------------------------------------------------ no display

TEST(LiveViewer, WithoutADisplayTheErrorSaysWhatToDo) {
  auto graph = std::make_shared<KeyframeGraph>();
  const char* saved = std::getenv("DISPLAY");
  const std::string previous = saved ? saved : "";
  unsetenv("DISPLAY");
  try {
    LiveViewer viewer(graph);
    FAIL() << "a viewer without a display";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("DISPLAY is not set"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("xvfb-run"), std::string::npos) << e.what();
  }
  setenv("DISPLAY", ":987", 1);  // no server there
  try {
    LiveViewer viewer(graph);
    FAIL() << "a viewer on a display that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open the X display ':987'"), std::string::npos)
        << e.what();
  }
  if (saved)
    setenv("DISPLAY", previous.c_str(), 1);
  else
    unsetenv("DISPLAY");
}

// ------------------------------------------------------------------ closing the window

namespace {
/// Opens a viewer, keeps MRPT's window thread busy from another window for longer than the old
/// deadline, and closes the viewer. Ends the process (a death test's child: the window thread
/// lives to the process's end and must not see the test's X server go): 0 if the close waited
/// for the thread, 1 if not. `display`: the X display it opens its windows on.
[[noreturn]] void closeAViewerWhileTheWindowThreadIsBusy(const std::string& display) {
  setenv("DISPLAY", display.c_str(), 1);  // in the child only: the test's process keeps its own
  auto viewer = std::make_unique<LiveViewer>(std::make_shared<KeyframeGraph>());
  mrpt::gui::CDisplayWindow3D other("another window", 160, 120);
  std::atomic<bool> busy{false}, done{false};
  other.sendFunctionToRunOnGUIThread([&] {
    busy = true;
    std::this_thread::sleep_for(25s);  // beyond the old deadlines (10 s, then 5 s)
    done = true;
  });
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (!busy && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(10ms);
  if (!busy) {
    std::fprintf(stderr, "the window thread never ran the other window's function\n");
    std::_Exit(2);
  }
  viewer.reset();
  std::fprintf(stderr, done ? "the viewer closed once the window thread was free\n"
                            : "the viewer freed its window while the window thread was busy\n");
  std::_Exit(done ? 0 : 1);
}
}  // namespace

// MRPT's window thread, shared by every window of the process, draws at the idle priority: on
// a machine whose cores are all busy it can be long in coming to the viewer's last requests.
// The viewer must not free its window before the thread has handled them; it did after a
// deadline (10 s, 5 s more for the last picture, then MRPT's own wait in the window's
// destructor), and freeing the window with requests queued corrupts the heap (most likely the
// "double free or corruption" after the last frame of a CI run with two tests on two cores).
TEST(LiveViewer, ClosingWaitsForTheWindowThreadHoweverLongItIsBusy) {
#ifdef SLAMDUNK_SANITIZED
  GTEST_SKIP() << "sanitizer build: the window system is not instrumented (test_gui_apps.cpp)";
#endif
  if (const auto why = test::missingDisplayTools()) GTEST_SKIP() << *why;
  const std::string dir = test::scratchDir("LiveViewer_BusyWindowThread");
  test::VirtualDisplay display(dir + "/xvfb.log");
  if (display.name().empty()) GTEST_SKIP() << "no X server could be started (Xvfb)";
  // Forked here, where this process has no thread but the main one.
  EXPECT_EXIT(closeAViewerWhileTheWindowThreadIsBusy(display.name()), testing::ExitedWithCode(0),
              "the viewer closed once the window thread was free");
}
