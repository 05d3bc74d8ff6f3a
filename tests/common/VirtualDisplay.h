#pragma once
// A virtual X server (Xvfb) for tests of programs with windows: started on a display number it
// picks itself, gone with the object. Tests skip, saying why, where it cannot start.

#include "ChildProcess.h"
#include "TestData.h"

#include <opencv2/core.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace slamdunk::test {

class VirtualDisplay {
 public:
  /// Starts Xvfb (1280x1024, 24 bits); its output goes to `logFile`.
  explicit VirtualDisplay(const std::string& logFile);
  /// ":N", or empty when the server did not start.
  const std::string& name() const { return name_; }

  /// Waits up to `seconds` for a window whose title contains `title`.
  bool waitForWindow(const std::string& title, double seconds) const;
  /// The X id of the first window whose title contains `title` ("" if none).
  std::string windowId(const std::string& title) const;
  /// The whole screen, saved to `png` and read back (empty on failure).
  cv::Mat screenshot(const std::string& png) const;
  /// Types a key (xdotool key name: "space", "s", "Right", "q") into the window named `title`.
  bool sendKey(const std::string& title, const std::string& key) const;

 private:
  std::unique_ptr<ChildProcess> server_;
  std::string name_;
};

/// Why a test of windows cannot run here (a tool missing), or nullopt. `programs`: what the
/// test needs besides Xvfb, xwininfo and import (e.g. "xdotool", "SceneViewer3D").
std::optional<std::string> missingDisplayTools(const std::vector<std::string>& programs = {});

/// Pixels of clearly coloured light (HSV saturation and value above a third) with a hue in
/// [hueFrom, hueTo] (OpenCV's 0-180 scale): drawn content, not grey chrome or background.
int colouredPixels(const cv::Mat& bgr, int hueFrom, int hueTo);
/// Pixels within `tolerance` (per channel) of an exact colour (BGR).
int pixelsNear(const cv::Mat& bgr, const cv::Vec3b& colour, int tolerance);

}  // namespace slamdunk::test

/// Declares `display`, a VirtualDisplay whose server writes to `dir`/xvfb.log. Skips (or fails,
/// see SLAMDUNK_SKIP) the current test where a tool it needs is missing (missingDisplayTools(),
/// given the test's own programs, if any) or the server does not start.
#define REQUIRE_VIRTUAL_DISPLAY(display, dir, ...)                                                \
  if (const auto why = ::slamdunk::test::missingDisplayTools({__VA_ARGS__})) SLAMDUNK_SKIP(*why); \
  ::slamdunk::test::VirtualDisplay display((dir) + "/xvfb.log");                                  \
  if (display.name().empty())                                                                     \
  SLAMDUNK_SKIP(                                                                                  \
      "no X server could be started (Xvfb): " << ::slamdunk::test::readFile((dir) + "/xvfb.log"))
