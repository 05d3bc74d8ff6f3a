// The process's exit after a viewer: MRPT gives its window thread 100 ms to end before
// wxWidgets' static objects are destroyed; a window thread still running then corrupts the heap
// ("double free or corruption" after the last frame of CI runs). The viewer's thread draws at
// the idle priority and can take much longer on a busy machine, so the exit waits for it.
// Includes MRPT's WxSubsystem.h (and so wxWidgets' headers) to keep the thread busy at exit.

#include <slamdunk/viewer/LiveViewer.h>

#include "TestData.h"
#include "VirtualDisplay.h"

#include <gtest/gtest.h>
#include <mrpt/gui/WxSubsystem.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

using namespace slamdunk;
using namespace slamdunk::viewer;
using mrpt::gui::WxSubsystem;

namespace {

std::atomic<bool> workDone{false};

/// Registered before the viewer: runs after the viewer's exit step.
void reportAtTheEnd() {
  const bool ended = !WxSubsystem::GetWxMainThreadInstance().m_wxMainThreadId.joinable();
  std::fprintf(stderr, "at the end: work %s, window thread %s\n", workDone ? "done" : "not done",
               ended ? "ended" : "still running");
}

/// Registered after the viewer closed: runs first at exit, and gives the window thread 1.5 s
/// of work (far beyond MRPT's 100 ms), as a starved thread would need.
void keepTheWindowThreadBusy() {
  auto* request = new WxSubsystem::TRequestToWxMainThread[1];
  request->OPCODE = 800;  // run a function on the window thread
  request->userFunction = [] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    workDone = true;
  };
  WxSubsystem::pushPendingWxRequest(request);
}

/// A death test's child: opens and closes a viewer, then exits normally.
[[noreturn]] void openCloseAndExit(const std::string& display) {
  setenv("DISPLAY", display.c_str(), 1);  // in the child only
  std::atexit(reportAtTheEnd);
  { LiveViewer viewer(std::make_shared<KeyframeGraph>()); }
  std::atexit(keepTheWindowThreadBusy);
  std::exit(0);
}

}  // namespace

TEST(LiveViewer, ExitWaitsForTheWindowThreadToEnd) {
#ifdef SLAMDUNK_SANITIZED
  GTEST_SKIP() << "sanitizer build: the window system is not instrumented (test_gui_apps.cpp)";
#endif
  if (const auto why = test::missingDisplayTools()) GTEST_SKIP() << *why;
  const std::string dir = test::scratchDir("LiveViewer_Exit");
  test::VirtualDisplay display(dir + "/xvfb.log");
  if (display.name().empty()) GTEST_SKIP() << "no X server could be started (Xvfb)";
  EXPECT_EXIT(openCloseAndExit(display.name()), testing::ExitedWithCode(0),
              "at the end: work done, window thread ended");
}
