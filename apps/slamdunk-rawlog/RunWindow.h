#pragma once
// slamdunk-rawlog --gui: the live viewer's window over an offline run. It shows each frame as it
// is processed, and its keys pause the run (space) or step it (s, right arrow): the run waits
// in RawlogSlamRun::beforeFrame, which does not count towards its speed.

#include <slamdunk/apps/RawlogSlamRun.h>

#include <memory>

namespace slamdunk {

class RunWindow {
 public:
  /// Opens the window and hooks it to `run`; with `paused`, the run waits for a key before its
  /// first frame. `log`: where to say that the run is paused (empty: nowhere). Throws
  /// std::runtime_error in a build without the viewer.
  RunWindow(apps::RawlogSlamRun& run, bool paused, std::function<void(const std::string&)> log);
  ~RunWindow();
  /// Shows the map after the run's last optimization.
  void flush();
  /// Until the window is closed (or q is pressed in it).
  void waitUntilClosed();

 private:
  struct Viewer;
  std::unique_ptr<Viewer> viewer_;
};

}  // namespace slamdunk
