// MRPT's own viewers on this project's outputs: SceneViewer3D opens the .3Dscene the apps
// write, and RawLogViewer starts with the map plug-in. Each runs under a virtual X server
// (Xvfb, installed by scripts/install-deps.sh), stays up, prints no error, and its screenshot
// shows what it should. Skips with a message where no X server can be started.
#include "ChildProcess.h"
#include "TestData.h"
#include "VirtualDisplay.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

using namespace slamdunk;
namespace fs = std::filesystem;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

using test::readFile;

/// Lines of a viewer's output that report a failure (GTK's own layout warnings, which a
/// window without a window manager triggers, are not the viewer's errors).
std::vector<std::string> errorLines(const std::string& output) {
  std::vector<std::string> found;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    std::string lower = line;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const char* word : {"error", "exception", "abort", "segmentation", "cannot", "failed to"})
      if (lower.find(word) != std::string::npos) {
        found.push_back(line);
        break;
      }
  }
  return found;
}

/// Screenshots of the whole display (saved to `png`) until `shows` holds for one, the viewer
/// exits, or 120 s pass (a deadline a viewer that draws never reaches): the last screenshot.
template <class Shows>
cv::Mat screenshotShowing(const test::VirtualDisplay& display, test::ChildProcess& viewer,
                          const std::string& png, Shows shows) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  for (;;) {
    const cv::Mat shot = display.screenshot(png);
    if ((!shot.empty() && shows(shot)) || !viewer.alive() || std::chrono::steady_clock::now() > end)
      return shot;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
}

/// What runViewer() saw: the last screenshot and the viewer's output.
struct ViewerRun {
  cv::Mat shot;
  std::string output;
  double secondsShown = 0;  ///< from its window's appearing to its stop
};

/// A viewer (`argv`) under `display`: its window titled `title` appears, screenshots are taken
/// until `shows` holds for one (screenshotShowing), and it is stopped, still running and with
/// no error in its output. Its output (line-buffered, whole when it is stopped) goes to
/// dir/viewer.log, the last screenshot to dir/viewer.png.
template <class Shows>
void runViewer(const test::VirtualDisplay& display, const std::vector<std::string>& argv,
               const std::string& title, const std::string& dir, Shows shows, ViewerRun& run) {
  std::vector<std::string> command = {"stdbuf", "-oL", "-eL"};
  command.insert(command.end(), argv.begin(), argv.end());
  const std::string log = dir + "/viewer.log";
  test::ChildProcess viewer(command, {"DISPLAY=" + display.name()}, log);
  ASSERT_TRUE(viewer.started());
  ASSERT_TRUE(display.waitForWindow(title, 60))
      << "no " << argv[0] << " window titled " << title << "; output:\n"
      << readFile(log);
  const auto shown = std::chrono::steady_clock::now();
  run.shot = screenshotShowing(display, viewer, dir + "/viewer.png", shows);
  EXPECT_TRUE(viewer.alive()) << argv[0] << " exited; output:\n" << readFile(log);
  viewer.stop();
  run.secondsShown =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - shown).count();
  run.output = readFile(log);
  const auto errors = errorLines(run.output);
  EXPECT_TRUE(errors.empty()) << errors.front();
  ASSERT_FALSE(run.shot.empty());
}

/// The keyframe frustums and graph edges are drawn orange (255, 160, 0): SceneViewer3D's own
/// empty view has no orange, only its grey grid and red, green and blue axes. The map's cloud
/// has orange points too: measured 546 orange pixels with the frustums and edges, 289 without
/// (slamdunk-render --no-frustums --no-edges); 643 and 369 coloured pixels.
constexpr int kFewestOrange = 420, kFewestColoured = 480;
int orangePixels(const cv::Mat& shot) { return test::colouredPixels(shot, 10, 25); }
int colouredPixels(const cv::Mat& shot) { return test::colouredPixels(shot, 0, 180); }

/// The fraction of the screen drawn light: the RawLogViewer window (light GTK theme) on the
/// black root window (measured 16.0-17.0 % of the 1280x1024 screen).
constexpr double kLightest = 0.10;
double lightFraction(const cv::Mat& shot) {
  cv::Mat grey, light;
  cv::cvtColor(shot, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, light, 200, 255, cv::THRESH_BINARY);
  return cv::countNonZero(light) / double(grey.total());
}

}  // namespace

TEST(MrptViewers, SceneViewer3DShowsTheSavedScene) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Viewers_SceneViewer3D");
  REQUIRE_VIRTUAL_DISPLAY(display, dir, "SceneViewer3D");
  // A map of the first 120 frames, and its scene as slamdunk-render writes it.
  const auto slam = test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " -t " +
                                     q(dir + "/t.txt") + " --max-frames 120 -q" + " --save-map " +
                                     q(dir + "/m.map"));
  ASSERT_EQ(slam.exitCode, 0) << slam.output;
  const auto render =
      test::runCommand(test::toolPath("slamdunk-render") + " " + q(dir + "/m.map") + " " +
                       q(dir + "/m.png") + " --scene " + q(dir + "/m.3Dscene"));
  ASSERT_EQ(render.exitCode, 0) << render.output;

  // The window is titled after the scene; it loads, then draws: screenshots until the map is
  // on the screen.
  ViewerRun run;
  ASSERT_NO_FATAL_FAILURE(runViewer(
      display, {"SceneViewer3D", dir + "/m.3Dscene"}, "[m.3Dscene]", dir,
      [](const cv::Mat& s) {
        return orangePixels(s) >= kFewestOrange && colouredPixels(s) >= kFewestColoured;
      },
      run));
  const int orange = orangePixels(run.shot);
  const int coloured = colouredPixels(run.shot);
  std::cout << "SceneViewer3D: " << orange << " orange pixels, " << coloured << " coloured in all ("
            << dir << "/viewer.png), " << run.secondsShown << " s after its window appeared\n";
  EXPECT_GE(orange, kFewestOrange) << "no keyframe frustum on the screen within 120 s: " << dir;
  EXPECT_GE(coloured, kFewestColoured) << "the map is not on the screen within 120 s: " << dir;
}

TEST(MrptViewers, RawLogViewerStartsWithTheMapPlugin) {
#ifdef SLAMDUNK_SANITIZED
  GTEST_SKIP() << "the plug-in is ASan-instrumented here and RawLogViewer is not: it cannot load "
                  "it (the ASan runtime must come first); the Release suite runs this test";
#endif
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Viewers_RawLogViewer");
  REQUIRE_VIRTUAL_DISPLAY(display, dir, "RawLogViewer");
  // Screenshots until the window is drawn and the plug-in's loading is reported.
  const std::string loading = std::string("Loading plugin libraries: ") + SLAMDUNK_MAPS_PLUGIN;
  ViewerRun run;
  ASSERT_NO_FATAL_FAILURE(runViewer(
      display, {"RawLogViewer", "-l", SLAMDUNK_MAPS_PLUGIN, rawlog},
      "RawlogViewer - Part of the MRPT project", dir,
      [&](const cv::Mat& s) {
        return lightFraction(s) >= kLightest &&
               readFile(dir + "/viewer.log").find(loading) != std::string::npos;
      },
      run));
  // It names the plug-in it loads (and, runViewer() checked, says nothing about failing to).
  EXPECT_NE(run.output.find(loading), std::string::npos) << run.output;
  // Not blank: the window (light GTK theme) covers part of the black root window.
  const double light = lightFraction(run.shot);
  std::cout << "RawLogViewer: " << light * 100 << " % of the screen drawn light (" << dir
            << "/viewer.png), " << run.secondsShown << " s after its window appeared\n";
  EXPECT_GE(light, kLightest) << "the window was not drawn within 120 s";
}
