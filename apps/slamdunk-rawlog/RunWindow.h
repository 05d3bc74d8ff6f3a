#pragma once
// slamdunk-rawlog --gui: the live viewer's window over an offline run. It shows each frame as it
// is processed, and its keys pause the run (space) or step it (s, right arrow): the run waits
// in RawlogSlamRun::beforeFrame, which does not count towards its speed.
//
// The window lives in a plug-in (slamdunk-rawlog-gui.so, RunWindowPlugin.cpp) loaded only when
// --gui is given: a run without it does not load the GUI libraries (X11, wxWidgets, Qt: about a
// quarter of the program's memory at start).

#include <slamdunk/apps/RawlogSlamRun.h>

#include <functional>
#include <memory>
#include <string>

namespace slamdunk {

/// What the plug-in implements.
class RunWindowBackend {
 public:
  virtual ~RunWindowBackend() = default;
  virtual void flush() = 0;
  virtual void waitUntilClosed() = 0;
};

class RunWindow {
 public:
  /// Loads the plug-in, opens the window and hooks it to `run`; with `paused`, the run waits for
  /// a key before its first frame. `log`: where to say that the run is paused (empty: nowhere).
  /// Throws std::runtime_error when the plug-in cannot be loaded (a build without the viewer).
  RunWindow(apps::RawlogSlamRun& run, bool paused, std::function<void(const std::string&)> log);
  ~RunWindow();
  /// Shows the map after the run's last optimization.
  void flush() { backend_->flush(); }
  /// Until the window is closed (or q is pressed in it).
  void waitUntilClosed() { backend_->waitUntilClosed(); }

 private:
  std::unique_ptr<RunWindowBackend> backend_;
};

/// The plug-in's entry point (C linkage, looked up by name).
using OpenRunWindowFunction = RunWindowBackend* (*)(apps::RawlogSlamRun& run, bool paused,
                                                    std::function<void(const std::string&)> log);
constexpr const char* kOpenRunWindowSymbol = "slamdunkOpenRunWindow";

}  // namespace slamdunk
