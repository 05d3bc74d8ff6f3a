#include "VirtualDisplay.h"

#include "TestData.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <regex>
#include <sstream>
#include <thread>

namespace slamdunk::test {

namespace {
bool onPath(const std::string& program) {
  return runCommand("command -v " + program + " >/dev/null").exitCode == 0;
}
}  // namespace

VirtualDisplay::VirtualDisplay(const std::string& logFile) {
  int fds[2];
  if (pipe(fds) != 0) return;
  const std::string fdArg = std::to_string(fds[1]);
  // -noreset: by default the server resets when its last client disconnects (e.g. xwininfo
  // between two checks), and a program that is just connecting then fails.
  server_ = std::make_unique<ChildProcess>(
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

bool VirtualDisplay::waitForWindow(const std::string& title, double seconds) const {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (!windowId(title).empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  return false;
}

std::string VirtualDisplay::windowId(const std::string& title) const {
  const auto tree = runCommand("xwininfo -display " + name_ + " -root -tree");
  std::istringstream lines(tree.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("\"") == std::string::npos || line.find(title) == std::string::npos) continue;
    std::smatch m;
    if (std::regex_search(line, m, std::regex("(0x[0-9a-fA-F]+)"))) return m[1];
  }
  return {};
}

cv::Mat VirtualDisplay::screenshot(const std::string& png) const {
  const auto r = runCommand("import -display " + name_ + " -window root " + shellQuote(png));
  return r.exitCode == 0 ? cv::imread(png) : cv::Mat();
}

bool VirtualDisplay::sendKey(const std::string& title, const std::string& key) const {
  // No window manager here: give the window the keyboard focus, then type through XTEST (real
  // key events, which GTK takes; sent events may be ignored). Only a mapped (visible) window
  // takes the focus: a window just created may not be yet, so try for a few seconds.
  std::string regex;
  for (char c : title) {
    if (std::string("\\.^$|?*+()[]{}").find(c) != std::string::npos) regex += '\\';
    regex += c;
  }
  const std::string command = "DISPLAY=" + name_ + " xdotool search --onlyvisible --name " +
                              shellQuote(regex) + " windowfocus --sync key " + key;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (runCommand(command).exitCode != 0) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return true;
}

std::optional<std::string> missingDisplayTools(const std::vector<std::string>& programs) {
  for (const char* tool : {"Xvfb", "xwininfo", "import"})
    if (!onPath(tool))
      return std::string(tool) + " is not installed (scripts/install-deps.sh installs xvfb, " +
             "x11-utils, imagemagick and xdotool)";
  for (const auto& p : programs)
    if (!onPath(p)) return p + " is not installed (see scripts/install-deps.sh)";
  return std::nullopt;
}

int colouredPixels(const cv::Mat& bgr, int hueFrom, int hueTo) {
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  cv::Mat mask;
  cv::inRange(hsv, cv::Scalar(hueFrom, 85, 85), cv::Scalar(hueTo, 255, 255), mask);
  return cv::countNonZero(mask);
}

int pixelsNear(const cv::Mat& bgr, const cv::Vec3b& colour, int tolerance) {
  cv::Mat mask;
  const cv::Scalar lo(colour[0] - tolerance, colour[1] - tolerance, colour[2] - tolerance);
  const cv::Scalar hi(colour[0] + tolerance, colour[1] + tolerance, colour[2] + tolerance);
  cv::inRange(bgr, lo, hi, mask);
  return cv::countNonZero(mask);
}

}  // namespace slamdunk::test
