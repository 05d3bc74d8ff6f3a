// MRPT's own viewers on this project's outputs: SceneViewer3D opens the .3Dscene the apps
// write, and RawLogViewer starts with the map plug-in. Each runs under a virtual X server
// (Xvfb, installed by scripts/install-deps.sh), stays up, prints no error, and its screenshot
// shows what it should. Skips with a message where no X server can be started.
#include "TestData.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

extern char** environ;

using namespace slamdunk;
namespace fs = std::filesystem;
using std::chrono::steady_clock;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

bool onPath(const std::string& program) {
  return test::runCommand("command -v " + program + " >/dev/null").exitCode == 0;
}

/// A child process started with posix_spawn: stdout and stderr go to `logFile`.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::vector<std::string>& extraEnv,
        const std::string& logFile) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::vector<std::string> envStrings(extraEnv);
    for (char** e = environ; *e; ++e) envStrings.emplace_back(*e);
    std::vector<char*> env;
    for (auto& e : envStrings) env.push_back(e.data());
    env.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    // Its own process group, so that stopping it also stops what it started.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    if (posix_spawnp(&pid_, args[0], &actions, &attr, args.data(), env.data()) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
  }
  ~Child() { stop(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool started() const { return pid_ > 0; }
  /// Still running (not exited, not killed).
  bool alive() {
    if (pid_ <= 0 || exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) exited_ = true;
    return !exited_;
  }
  void stop() {
    if (pid_ <= 0 || !alive()) return;
    kill(-pid_, SIGTERM);
    for (int i = 0; i < 50 && alive(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (alive()) kill(-pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    exited_ = true;
  }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
};

/// Xvfb on a display it picks itself (-displayfd), gone when this object is.
class VirtualDisplay {
 public:
  explicit VirtualDisplay(const std::string& logFile) {
    int fds[2];
    if (pipe(fds) != 0) return;
    const std::string fdArg = std::to_string(fds[1]);
    server_ = std::make_unique<Child>(
        // -noreset: by default the server resets whenever its last client disconnects (each
        // xwininfo poll below), and a viewer connecting during a reset fails to open the display.
        std::vector<std::string>{"Xvfb", "-displayfd", fdArg, "-screen", "0", "1280x1024x24",
                                 "-nolisten", "tcp", "-noreset"},
        std::vector<std::string>{}, logFile);  // inherits fds[1]: pipe() sets no O_CLOEXEC
    close(fds[1]);
    pollfd p{fds[0], POLLIN, 0};
    char buf[32] = {};
    if (server_->started() && poll(&p, 1, 15000) == 1 && read(fds[0], buf, sizeof buf - 1) > 0)
      name_ = ":" + std::to_string(std::atoi(buf));
    close(fds[0]);
  }
  /// ":N", or empty when the server did not start.
  const std::string& name() const { return name_; }

  /// Waits up to `seconds` for a window whose title contains `title`; gives up early when
  /// `program` exits.
  bool waitForWindow(const std::string& title, double seconds, Child& program) const {
    const auto end = steady_clock::now() + std::chrono::duration<double>(seconds);
    while (steady_clock::now() < end && program.alive()) {
      const auto tree = test::runCommand("xwininfo -display " + name_ + " -root -tree");
      if (tree.output.find(title) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
    return false;
  }
  cv::Mat screenshot(const std::string& png) const {
    const auto r = test::runCommand("import -display " + name_ + " -window root " + q(png));
    return r.exitCode == 0 ? cv::imread(png) : cv::Mat();
  }

 private:
  std::unique_ptr<Child> server_;
  std::string name_;
};

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

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

/// Pixels of clearly coloured light (HSV saturation and value above a third) with a hue in
/// [hueFrom, hueTo] (OpenCV's 0-180 scale): the map's cloud and frustums, not window chrome,
/// text or background, which are grey.
int colouredPixels(const cv::Mat& bgr, int hueFrom, int hueTo) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  cv::Mat mask;
  cv::inRange(hsv, cv::Scalar(hueFrom, 85, 85), cv::Scalar(hueTo, 255, 255), mask);
  return cv::countNonZero(mask);
}

/// A display or the viewers are missing: the test skips with why.
std::optional<std::string> missingTools(const std::vector<std::string>& viewers) {
  for (const char* tool : {"Xvfb", "xwininfo", "import"})
    if (!onPath(tool))
      return std::string(tool) + " is not installed (scripts/install-deps.sh installs xvfb, " +
             "x11-utils and imagemagick)";
  for (const auto& v : viewers)
    if (!onPath(v)) return v + " is not installed (Debian package mrpt-apps)";
  return std::nullopt;
}

/// A viewer on its own virtual display, its window up (or why not).
struct RunningViewer {
  std::unique_ptr<VirtualDisplay> display;  // declared first: outlives the viewer
  std::unique_ptr<Child> viewer;
  bool noServer = false;  ///< Xvfb could not start: the test skips
  std::string failure;    ///< no window: what the viewer printed
};

/// Starts `argv` on a fresh Xvfb and waits for a window titled `title`. A viewer that could
/// not open the display (seen once in CI: "Unable to initialize GTK+") is started again on a
/// new server, up to three times; every attempt's output is kept for the failure message.
RunningViewer startViewer(const std::vector<std::string>& argv, const std::string& title,
                          const std::string& dir) {
  RunningViewer run;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    run.viewer.reset();
    run.display = std::make_unique<VirtualDisplay>(dir + "/xvfb.log");
    if (run.display->name().empty()) {
      run.noServer = true;
      run.failure = readFile(dir + "/xvfb.log");
      return run;
    }
    run.viewer = std::make_unique<Child>(
        argv, std::vector<std::string>{"DISPLAY=" + run.display->name()}, dir + "/viewer.log");
    if (run.viewer->started() && run.display->waitForWindow(title, 60, *run.viewer)) {
      run.failure.clear();
      return run;
    }
    const std::string output = readFile(dir + "/viewer.log");
    run.failure += "attempt " + std::to_string(attempt) + " on " + run.display->name() +
                   (run.viewer->alive() ? " (still running, no window)" : " (exited)") + ":\n" +
                   output + "\nXvfb:\n" + readFile(dir + "/xvfb.log") + "\n";
    const bool displayRefused = output.find("Unable to initialize GTK") != std::string::npos ||
                                output.find("cannot open display") != std::string::npos;
    if (!displayRefused) break;
  }
  return run;
}

}  // namespace

TEST(MrptViewers, SceneViewer3DShowsTheSavedScene) {
  if (const auto why = missingTools({"SceneViewer3D"})) GTEST_SKIP() << *why;
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Viewers_SceneViewer3D");
  // A map of the first 120 frames, and its scene as slamdunk-render writes it.
  const auto slam = test::runCommand(test::toolPath("slamdunk-rawlog") + " " + q(rawlog) + " -t " +
                                     q(dir + "/t.txt") + " --max-frames 120 -q" + " --save-map " +
                                     q(dir + "/m.map"));
  ASSERT_EQ(slam.exitCode, 0) << slam.output;
  const auto render =
      test::runCommand(test::toolPath("slamdunk-render") + " " + q(dir + "/m.map") + " " +
                       q(dir + "/m.png") + " --scene " + q(dir + "/m.3Dscene"));
  ASSERT_EQ(render.exitCode, 0) << render.output;

  auto run = startViewer({"stdbuf", "-oL", "-eL", "SceneViewer3D", dir + "/m.3Dscene"},
                         "[m.3Dscene]", dir);
  if (run.noServer) GTEST_SKIP() << "no X server could be started (Xvfb): " << run.failure;
  ASSERT_TRUE(run.failure.empty()) << "no SceneViewer3D window with the scene's name:\n"
                                   << run.failure;
  const VirtualDisplay& display = *run.display;
  Child& viewer = *run.viewer;
  std::this_thread::sleep_for(std::chrono::seconds(5));  // it loads, then draws
  const cv::Mat shot = display.screenshot(dir + "/viewer.png");
  EXPECT_TRUE(viewer.alive()) << "SceneViewer3D exited; output:\n" << readFile(dir + "/viewer.log");
  viewer.stop();
  ASSERT_FALSE(shot.empty());
  // The keyframe frustums and graph edges are drawn orange (255, 160, 0): SceneViewer3D's own
  // empty view has no orange, only its grey grid and red, green and blue axes.
  const int orange = colouredPixels(shot, 10, 25);
  const int coloured = colouredPixels(shot, 0, 180);
  std::cout << "SceneViewer3D: " << orange << " orange pixels, " << coloured << " coloured in all ("
            << dir << "/viewer.png)\n";
  EXPECT_GE(orange, 20) << "no keyframe frustum on the screen: " << dir;
  EXPECT_GE(coloured, 100) << "the map is not on the screen: " << dir;
  const auto errors = errorLines(readFile(dir + "/viewer.log"));
  EXPECT_TRUE(errors.empty()) << errors.front();
}

TEST(MrptViewers, RawLogViewerStartsWithTheMapPlugin) {
#ifdef SLAMDUNK_SANITIZED
  GTEST_SKIP() << "the plug-in is ASan-instrumented here and RawLogViewer is not: it cannot load "
                  "it (the ASan runtime must come first); the Release suite runs this test";
#endif
  if (const auto why = missingTools({"RawLogViewer"})) GTEST_SKIP() << *why;
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string dir = test::scratchDir("Viewers_RawLogViewer");
  auto run =
      startViewer({"stdbuf", "-oL", "-eL", "RawLogViewer", "-l", SLAMDUNK_MAPS_PLUGIN, rawlog},
                  "RawlogViewer - Part of the MRPT project", dir);
  if (run.noServer) GTEST_SKIP() << "no X server could be started (Xvfb): " << run.failure;
  ASSERT_TRUE(run.failure.empty()) << "no RawLogViewer window:\n" << run.failure;
  const VirtualDisplay& display = *run.display;
  Child& viewer = *run.viewer;
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const cv::Mat shot = display.screenshot(dir + "/viewer.png");
  EXPECT_TRUE(viewer.alive()) << "RawLogViewer exited; output:\n" << readFile(dir + "/viewer.log");
  viewer.stop();
  const std::string output = readFile(dir + "/viewer.log");
  // It names the plug-in it loads, and says nothing about failing to.
  EXPECT_NE(output.find(std::string("Loading plugin libraries: ") + SLAMDUNK_MAPS_PLUGIN),
            std::string::npos)
      << output;
  const auto errors = errorLines(output);
  EXPECT_TRUE(errors.empty()) << errors.front();
  // Not blank: the window (light GTK theme) covers part of the black root window.
  ASSERT_FALSE(shot.empty());
  cv::Mat grey, light;
  cv::cvtColor(shot, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, light, 200, 255, cv::THRESH_BINARY);
  const double lightFraction = cv::countNonZero(light) / double(grey.total());
  std::cout << "RawLogViewer: " << lightFraction * 100 << " % of the screen drawn light (" << dir
            << "/viewer.png)\n";
  EXPECT_GE(lightFraction, 0.05);
}
