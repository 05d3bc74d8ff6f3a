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
#include <mrpt/opengl/CPointCloudColoured.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

using namespace slamdunk;
using namespace slamdunk::viewer;
using namespace std::chrono_literals;

// ------------------------------------------------------------------ pause and step

namespace {
/// Polls `done()` until it holds or `limit` passes; false on timeout.
template <class Done>
bool within(std::chrono::seconds limit, Done done) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

/// within() a deadline only a hang reaches.
template <class Done>
bool within30s(Done done) {
  return within(30s, done);
}

/// One frame's waitForTurn(), on a thread of its own. No check passes by a wait running out:
/// held() waits until the thread is provably blocked (PlaybackControl::waiting()), passed()
/// until it has returned; either fails at the deadline.
class Frame {
 public:
  explicit Frame(PlaybackControl& control) : control_(control) {
    thread_ = std::thread([this] {
      control_.waitForTurn();
      returned_ = true;
    });
  }
  ~Frame() {
    if (!returned_) control_.release();  // a test that failed: let the thread go
    thread_.join();
  }
  /// True once waitForTurn() has returned; false if it has not within 30 s.
  bool passed() const {
    return within30s([&] { return returned_.load(); });
  }
  /// True once the thread is blocked in waitForTurn() (and so has not returned); false if it
  /// returned instead, or neither happened within 30 s.
  bool held() const {
    within30s([&] { return returned_ || control_.waiting() == 1; });
    return !returned_ && control_.waiting() == 1;
  }

 private:
  PlaybackControl& control_;
  std::atomic<bool> returned_{false};
  std::thread thread_;
};

/// A frame that must go through without waiting for anyone.
bool passes(PlaybackControl& control) { return Frame(control).passed(); }

/// A frame that must wait until `letGo` (togglePause, step or release) is called, and then go.
::testing::AssertionResult heldUntil(PlaybackControl& control, void (PlaybackControl::*letGo)()) {
  Frame next(control);
  if (!next.held()) return ::testing::AssertionFailure() << "it went through without waiting";
  (control.*letGo)();
  if (!next.passed()) return ::testing::AssertionFailure() << "it was held, then never let go";
  return ::testing::AssertionSuccess();
}
}  // namespace

// Each test ASSERTs: a frame let go by a failed check (~Frame releases the control) would
// make the checks after it meaningless.
TEST(PlaybackControl, RunsUntilPausedThenStepsOneFrameAtATime) {
  PlaybackControl c;
  ASSERT_TRUE(passes(c)) << "not paused: no waiting";
  EXPECT_EQ(c.waiting(), 0u);
  c.togglePause();
  EXPECT_TRUE(c.paused());
  ASSERT_TRUE(heldUntil(c, &PlaybackControl::togglePause))
      << "paused: the next frame waits; resumed: it goes";
  EXPECT_FALSE(c.paused());
  ASSERT_TRUE(passes(c)) << "resumed: no waiting";
}

TEST(PlaybackControl, StepLetsExactlyOneFrameThrough) {
  PlaybackControl c;
  c.togglePause();
  c.step();
  ASSERT_TRUE(passes(c)) << "the step's frame";
  EXPECT_TRUE(c.paused()) << "still paused after the step";
  ASSERT_TRUE(heldUntil(c, &PlaybackControl::step))
      << "one step, one frame: the next one waits, until the next step";
  c.step();
  c.step();
  ASSERT_TRUE(passes(c)) << "two steps: the first frame";
  ASSERT_TRUE(passes(c)) << "two steps: the second frame";
  ASSERT_TRUE(heldUntil(c, &PlaybackControl::release))
      << "two steps, two frames: a third one waits, until release()";
}

TEST(PlaybackControl, StepWhileRunningPausesAfterOneFrame) {
  PlaybackControl c;
  c.step();
  EXPECT_TRUE(c.paused());
  ASSERT_TRUE(passes(c)) << "the frame after the step";
  ASSERT_TRUE(heldUntil(c, &PlaybackControl::step))
      << "a step while running lets one frame through, not more; the next step the held one";
}

TEST(PlaybackControl, ResumeAndReleaseNeverWaitAgain) {
  PlaybackControl c;
  c.togglePause();
  c.togglePause();
  EXPECT_FALSE(c.paused());
  ASSERT_TRUE(passes(c)) << "paused and resumed: no waiting";
  c.togglePause();
  // The window closed while paused: the run must not hang.
  ASSERT_TRUE(heldUntil(c, &PlaybackControl::release))
      << "paused again: the next frame waits, until release()";
  EXPECT_FALSE(c.paused());
  c.togglePause();  // a key pressed after the window closed: still never waits
  c.step();
  ASSERT_TRUE(passes(c)) << "released, then paused: a frame was held";
  ASSERT_TRUE(passes(c)) << "released, then stepped: a second frame was held";
  EXPECT_EQ(c.waiting(), 0u);
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
  if (objects.empty()) SLAMDUNK_SKIP("no offscreen OpenGL (EGL) here");
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
  if (shot.empty()) SLAMDUNK_SKIP("no offscreen OpenGL (EGL) here");
  const Seen s = seen(shot);
  std::printf("40 frames (%s/scene.png): frustums %d, camera %d, coloured %d, inlier marks %d\n",
              dir.c_str(), s.frustums, s.camera, s.coloured, s.inliers);
  EXPECT_GE(s.camera, 10);
  EXPECT_GE(s.coloured, 1000);
  EXPECT_GE(s.inliers, 20);
}

namespace {
/// Every cloud point's colour in a scene, in order.
std::vector<mrpt::img::TColor> cloudColours(const mrpt::opengl::COpenGLScene& gl) {
  std::vector<mrpt::img::TColor> colours;
  for (size_t i = 0;; ++i) {
    const auto cloud = gl.getByClass<mrpt::opengl::CPointCloudColoured>(i);
    if (!cloud) break;
    for (size_t k = 0; k < cloud->size(); ++k) colours.push_back(cloud->getPointColor(k));
  }
  return colours;
}
}  // namespace

// The graph has a keyframe as soon as tracking made it; its image comes with its frame's
// batch, later (a frame later when the viewer is busy taking the previous one). A keyframe
// drawn meanwhile was left in the neutral colour for good: on a busy machine most of a live
// session's cloud was grey (GuiApps.LiveGuiShowsTheSession saw too few coloured pixels).
TEST(LiveMapSceneSmall, AKeyframeDrawnBeforeItsImageCameIsColouredWhenItComes) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  SlamSystem slam{SlamOptions()};
  RawlogReader reader(rawlog);
  std::vector<std::pair<KeyframeId, cv::Mat>> colours;
  for (size_t i = 0; i < 40; ++i) {
    auto obs = reader.next();
    ASSERT_TRUE(obs);
    obs->load();
    const TrackingResult r = slam.process(*obs);
    if (r.newKeyframe) colours.emplace_back(r.keyframeId, obs->intensityImage.asCvMatRef().clone());
  }
  ASSERT_GE(colours.size(), 1u);
  const auto graph = slam.graph();
  ViewerStatus status;
  // The images first, as when the viewer takes a keyframe's batch before drawing it.
  LiveMapScene onTime;
  mrpt::opengl::COpenGLScene onTimeGl;
  onTime.attachTo(onTimeGl);
  for (const auto& [id, image] : colours) onTime.setKeyframeColour(id, image);
  onTime.update(*graph, nullptr, status);
  // The keyframes drawn before their images came, then the images.
  LiveMapScene late;
  mrpt::opengl::COpenGLScene lateGl;
  late.attachTo(lateGl);
  late.update(*graph, nullptr, status);
  const auto grey = cloudColours(lateGl);
  for (const auto& [id, image] : colours) late.setKeyframeColour(id, image);
  late.update(*graph, nullptr, status);

  const auto expected = cloudColours(onTimeGl), recoloured = cloudColours(lateGl);
  ASSERT_GT(expected.size(), 1000u);
  ASSERT_EQ(recoloured.size(), expected.size());
  const auto tinted = [](const std::vector<mrpt::img::TColor>& c) {
    return std::count_if(c.begin(), c.end(), [](const auto& p) { return p.R != p.G; });
  };
  std::printf("%zu cloud points: %zu tinted before the images came, %zu after, %zu on time\n",
              expected.size(), size_t(tinted(grey)), size_t(tinted(recoloured)),
              size_t(tinted(expected)));
  EXPECT_EQ(tinted(grey), 0) << "without its image a keyframe's cloud is in the neutral grey";
  EXPECT_GT(tinted(expected), static_cast<long>(expected.size() / 2));
  size_t differ = 0;
  for (size_t i = 0; i < expected.size(); ++i)
    differ += expected[i].R != recoloured[i].R || expected[i].G != recoloured[i].G ||
              expected[i].B != recoloured[i].B;
  EXPECT_EQ(differ, 0u) << "of " << expected.size() << " points coloured late";
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
  // MRPT's constructor stops waiting for the window after 6 s, and a window not made yet drops
  // the function sent to it without a word: waited for as long as the viewer would wait.
  if (!within(300s, [&] { return other.isOpen(); })) {
    std::fprintf(stderr, "the window thread never opened the other window\n");
    std::_Exit(3);
  }
  std::atomic<bool> busy{false}, done{false};
  other.sendFunctionToRunOnGUIThread([&] {
    busy = true;
    std::this_thread::sleep_for(16s);  // beyond the old deadlines (10 s, then 5 s)
    done = true;
  });
  // The thread draws at the idle priority: beside busy loops on every core it may take minutes
  // to come to the function (as long as the viewer would wait for it, 300 s).
  if (!within(300s, [&] { return busy.load(); })) {
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
  const std::string dir = test::scratchDir("LiveViewer_BusyWindowThread");
  REQUIRE_VIRTUAL_DISPLAY(display, dir);
  // Forked here, where this process has no thread but the main one.
  EXPECT_EXIT(closeAViewerWhileTheWindowThreadIsBusy(display.name()), testing::ExitedWithCode(0),
              "the viewer closed once the window thread was free");
}
