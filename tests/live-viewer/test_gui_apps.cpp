// --gui on slamdunk-rawlog and slamdunk-live, under a virtual X server (Xvfb): the window
// shows the map (its screenshot has the keyframe frustums, the current camera and the cloud's
// colours), keys pause and step an offline run, and the offline results stay the same with the
// viewer, paused or not. Skips with a message where no X server can be started.

#include "ChildProcess.h"
#include "TestData.h"
#include "VirtualDisplay.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

using namespace slamdunk;
namespace fs = std::filesystem;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

using test::readFile;

/// How long what the viewer's window thread does may take (its window to appear, its close at
/// the app's end): it runs at the idle CPU priority, and beside busy loops on every core
/// (scripts/repeat-gui-tests.sh) it gets the CPU only now and then. The viewer itself waits
/// that long for it (LiveViewer.cpp). Waits return as soon as their condition holds.
constexpr double kWindowThreadSeconds = 300;

/// Polls `done()` every 100 ms for up to `seconds`; false if it never held (the caller fails).
bool waitUntil(const std::function<bool()>& done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

/// Waits up to `seconds` for `text` in a log file.
bool waitForText(const std::string& log, const std::string& text, double seconds) {
  return waitUntil([&] { return readFile(log).find(text) != std::string::npos; }, seconds);
}

// The viewer's colours (LiveMapScene), BGR.
// (The loop edges' magenta is also in the synthetic room's textures: checked offscreen instead,
// in test_live_viewer.cpp, with the cloud hidden.)
const cv::Vec3b kFrustum(40, 170, 255), kCamera(255, 210, 0);

/// What the window's screenshot shows, in the window's 1024x640 area (no window manager: the
/// window sits at the top-left corner).
struct ScreenContent {
  int frustums = 0, camera = 0, coloured = 0;
};
ScreenContent contentOf(const cv::Mat& screen) {
  ScreenContent c;
  cv::Mat window =
      screen(cv::Rect(0, 0, std::min(1024, screen.cols), std::min(640, screen.rows))).clone();
  window(cv::Rect(0, 0, 308, 231)).setTo(cv::Scalar(0, 0, 0));  // not the camera image inset
  c.frustums = test::pixelsNear(window, kFrustum, 40);
  c.camera = test::pixelsNear(window, kCamera, 40);
  c.coloured = test::colouredPixels(window, 0, 180);
  return c;
}

/// Screenshots every second until one shows at least `frustums` frustum pixels, `camera`
/// camera pixels and `coloured` coloured ones, or `seconds` pass; the last one taken. The
/// window is drawn at the idle CPU priority: on a machine kept busy by other work it may be
/// several seconds behind.
ScreenContent waitForContent(const test::VirtualDisplay& display, const std::string& png,
                             int frustums, int camera, int coloured, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  ScreenContent c;
  do {
    const cv::Mat shot = display.screenshot(png);
    if (!shot.empty()) c = contentOf(shot);
    if (c.frustums >= frustums && c.camera >= camera && c.coloured >= coloured) break;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  } while (std::chrono::steady_clock::now() < end);
  return c;
}

/// waitForContent(), expecting the least it waits for; what the screen showed.
ScreenContent expectOnScreen(const test::VirtualDisplay& display, const std::string& png,
                             int frustums, int camera, int coloured) {
  const ScreenContent c = waitForContent(display, png, frustums, camera, coloured, 120);
  EXPECT_GE(c.frustums, frustums) << "no keyframe frustums on the screen";
  EXPECT_GE(c.camera, camera) << "no current camera on the screen";
  EXPECT_GE(c.coloured, coloured) << "the map's cloud is not on the screen";
  return c;
}

/// The app's viewer window, titled `title`, appears (see kWindowThreadSeconds).
::testing::AssertionResult windowOpens(const test::VirtualDisplay& display,
                                       const std::string& title, const std::string& log) {
  if (display.waitForWindow(title, kWindowThreadSeconds)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "no viewer window '" << title << "':\n" << readFile(log);
}

/// The offline app's runs here take the synthetic loop's first 150 frames (its first turn, 13
/// keyframes): what the window shows and the keys do does not need the whole loop, and beside
/// busy loops (scripts/repeat-gui-tests.sh) every keyframe costs the starved window thread.
const std::string kFrames = "150";

/// A reference trajectory of the offline app, without the viewer.
std::string referenceRun(const std::string& rawlog, const std::string& dir) {
  const std::string t = dir + "/reference.txt";
  const auto r = test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " -t " +
                                  q(t) + " --max-frames " + kFrames + " -q");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return readFile(t);
}

/// The offline app on the loop's first kFrames frames with its viewer on `display` and
/// `guiOptions`; its trajectory to `trajectory`, its output to `log`.
std::unique_ptr<test::ChildProcess> startOfflineGui(const test::VirtualDisplay& display,
                                                    const std::string& rawlog,
                                                    const std::string& trajectory,
                                                    const std::string& log,
                                                    const std::vector<std::string>& guiOptions) {
  std::vector<std::string> argv = {test::toolPath("slamdunk-rawlog"),
                                   rawlog,
                                   "-t",
                                   trajectory,
                                   "--max-frames",
                                   kFrames,
                                   "--gui"};
  argv.insert(argv.end(), guiOptions.begin(), guiOptions.end());
  return std::make_unique<test::ChildProcess>(
      argv, std::vector<std::string>{"DISPLAY=" + display.name()}, log);
}

/// Body lines of a TUM file (its header names the run's inputs, which may differ).
std::string poses(const std::string& tum) {
  std::istringstream in(tum);
  std::string out;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') out += line + "\n";
  return out;
}

}  // namespace

#ifdef SLAMDUNK_SANITIZED
// The window system (wxWidgets, GTK, Mesa) is not instrumented and keeps allocations to the end
// of the process, which LeakSanitizer reports; the Release suite runs these tests. The viewer's
// own logic runs under the sanitizers in test_live_viewer.cpp (scene, pause and step).
#define SKIP_IF_SANITIZED() \
  GTEST_SKIP() << "sanitizer build: the window system is not instrumented (see the comment)"
#else
#define SKIP_IF_SANITIZED() (void)0
#endif

#define REQUIRE_DISPLAY(display, dir) \
  SKIP_IF_SANITIZED();                \
  REQUIRE_VIRTUAL_DISPLAY(display, dir, "xdotool")

TEST(GuiApps, RawlogGuiShowsTheMapAndLeavesTheResultsUnchanged) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("GuiApps_Rawlog");
  REQUIRE_DISPLAY(display, dir);
  const std::string reference = referenceRun(rawlog, dir);

  const std::string log = dir + "/app.log";
  const auto app =
      startOfflineGui(display, rawlog, dir + "/gui.txt", log, {"--gui-wait", "--json"});
  ASSERT_TRUE(app->started());
  const std::string title = "SlamDunk - synthetic_loop.rawlog";
  ASSERT_TRUE(windowOpens(display, title, log));
  // The run ends, the final map is drawn and the window stays (--gui-wait).
  ASSERT_TRUE(waitForText(log, "close the viewer window", 180)) << readFile(log);
  // The cloud is each keyframe's subsampled depth: its dots cover about 1/20-1/35 of the
  // window, depending on where the view follows the camera (the frustums, edges and status
  // line alone cover far less).
  const ScreenContent c = expectOnScreen(display, dir + "/screen.png", 50, 20, 1024 * 640 / 50);
  std::printf("rawlog --gui (%s/screen.png): frustums %d, camera %d, coloured %d\n", dir.c_str(),
              c.frustums, c.camera, c.coloured);

  // q closes the window and the app ends normally.
  EXPECT_TRUE(display.sendKey(title, "q"));
  EXPECT_EQ(app->wait(kWindowThreadSeconds), 0) << readFile(log);
  EXPECT_EQ(poses(readFile(dir + "/gui.txt")), poses(reference))
      << "the offline results changed with the viewer";
}

TEST(GuiApps, RawlogKeysPauseAndStepAndTheResultsStayTheSame) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("GuiApps_Keys");
  REQUIRE_DISPLAY(display, dir);
  const std::string reference = referenceRun(rawlog, dir);

  const std::string log = dir + "/app.log";
  const auto app = startOfflineGui(display, rawlog, dir + "/keys.txt", log, {"--gui-paused"});
  const std::string title = "SlamDunk - synthetic_loop.rawlog";
  ASSERT_TRUE(windowOpens(display, title, log));
  // The frames before which the app paused, in the order of its log ("paused before frame N",
  // printed each time it waits while paused).
  const auto pauses = [&] {
    std::vector<size_t> frames;
    const std::string text = readFile(log);
    const std::regex line("paused before frame ([0-9]+)\n");
    for (auto m = std::sregex_iterator(text.begin(), text.end(), line); m != std::sregex_iterator();
         ++m)
      frames.push_back(std::stoul((*m)[1]));
    return frames;
  };
  const auto upTo = [](size_t last) {
    std::vector<size_t> frames(last + 1);
    for (size_t i = 0; i <= last; ++i) frames[i] = i;
    return frames;
  };
  // --gui-paused: nothing is processed until a key says so; the app holds the first frame.
  ASSERT_TRUE(waitUntil([&] { return !pauses().empty(); }, 30)) << "no pause:\n" << readFile(log);
  EXPECT_TRUE(app->alive());
  EXPECT_EQ(pauses(), upTo(0)) << readFile(log);
  // Each step lets exactly one frame through: the next pause is before the next frame, every
  // frame paused before once, none skipped.
  size_t steps = 0;
  for (const char* key : {"s", "s", "Right"}) {
    ASSERT_TRUE(display.sendKey(title, key));
    ++steps;
    ASSERT_TRUE(waitUntil([&] { return pauses().back() >= steps; }, 30))
        << "no pause after step " << steps << ":\n"
        << readFile(log);
    EXPECT_EQ(pauses(), upTo(steps)) << readFile(log);
  }
  // Space runs; the run ends on its own, with the same trajectory as without the viewer.
  ASSERT_TRUE(display.sendKey(title, "space"));
  EXPECT_EQ(app->wait(180), 0) << readFile(log);
  // While paused, only the steps let frames through: the app paused before frames 0-3, each
  // once, and before no other frame (space ran the rest).
  EXPECT_EQ(pauses(), upTo(steps)) << "frames went on while paused:\n" << readFile(log);
  EXPECT_EQ(poses(readFile(dir + "/keys.txt")), poses(reference))
      << "pausing and stepping changed the offline results";
}

TEST(GuiApps, LiveGuiShowsTheSession) {
  REQUIRE_RAWLOG(rawlog, "synthetic_loop");
  const std::string dir = test::scratchDir("GuiApps_Live");
  REQUIRE_DISPLAY(display, dir);
  std::ofstream(dir + "/live.ini") << "[slamdunk-live]\nsource = REPLAY\n[REPLAY]\ndriver = "
                                      "replay\nrawlog = "
                                   << rawlog << "\n";
  const std::string log = dir + "/app.log";
  // 240 frames at 30 Hz: 8 s; the window stays open at the end.
  test::ChildProcess app(
      {test::toolPath("slamdunk-live"), "--config", dir + "/live.ini", "--trajectory",
       dir + "/live.txt", "--max-frames", "240", "--gui", "--gui-wait", "--json"},
      {"DISPLAY=" + display.name()}, log);
  const std::string title = "SlamDunk live - replay of";
  ASSERT_TRUE(windowOpens(display, title, log));
  ASSERT_TRUE(waitForText(log, "keyframes", 30)) << readFile(log);
  // Usually while the session runs; on a machine busy with other work, perhaps only after it.
  const ScreenContent c = expectOnScreen(display, dir + "/screen.png", 20, 20, 1024 * 640 / 40);
  const bool whileRunning = readFile(log).find("close the viewer window") == std::string::npos;
  std::printf("live --gui (%s/screen.png, %s): frustums %d, camera %d, coloured %d\n", dir.c_str(),
              whileRunning ? "while the session ran" : "after it ended", c.frustums, c.camera,
              c.coloured);
  ASSERT_TRUE(waitForText(log, "close the viewer window", 90)) << readFile(log);
  EXPECT_TRUE(display.sendKey(title, "q"));
  EXPECT_EQ(app.wait(kWindowThreadSeconds), 0) << readFile(log);
  const std::string out = readFile(log);
  // Every frame is accounted for (a machine busy with other work may make tracking drop some:
  // the viewer's cost is measured by scripts/benchmark-gui.sh, not here).
  EXPECT_EQ(test::jsonValue(out, "frames_received"), 240) << out;
  EXPECT_EQ(test::jsonValue(out, "frames_processed") + test::jsonValue(out, "frames_dropped"), 240)
      << out;
  EXPECT_EQ(test::jsonValue(out, "tracked"), test::jsonValue(out, "frames_processed")) << out;
}
