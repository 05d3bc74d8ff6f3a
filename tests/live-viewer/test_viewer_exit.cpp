// The end of the last viewer: it stops MRPT's window thread and waits for it to end, however
// long the thread is busy, before the process's exit. Left to the exit, the thread was stopped
// by an exit handler that runs after the destructors of the static objects the window system
// made once the thread had started (MRPT's request queue among them): the handler pushed its
// stop request into the freed queue, and the process aborted with "double free or corruption"
// after `slamdunk-live --gui --gui-wait` (issue 43; src/MrptWindowThread.h). The viewer's
// window thread draws at the idle priority and can be long in answering on a busy machine.
// Includes MRPT's WxSubsystem.h (and so wxWidgets' headers) to keep the thread busy.

#include <slamdunk/viewer/LiveViewer.h>

#include "TestData.h"
#include "VirtualDisplay.h"

#include <gtest/gtest.h>
#include <mrpt/gui/WxSubsystem.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

using namespace slamdunk;
using namespace slamdunk::viewer;
using mrpt::gui::WxSubsystem;

namespace {

std::atomic<bool> closing{false}, workDone{false};
std::string afterTheViewer;

bool windowThreadRuns() {
  return WxSubsystem::GetWxMainThreadInstance().m_wxMainThreadId.joinable();
}

/// At the process's exit (registered first: runs last), the whole story on one line.
void reportAtTheEnd() {
  std::fprintf(stderr, "%s; at the exit: window thread %s\n", afterTheViewer.c_str(),
               windowThreadRuns() ? "still running" : "ended");
}

/// Keeps the window thread busy from before the viewer begins to close until 1.5 s after it
/// began (far beyond MRPT's 100 ms), as a starved thread would be: the viewer's close, queued
/// after this, cannot be done before this ends.
void keepTheWindowThreadBusy() {
  auto* request = new WxSubsystem::TRequestToWxMainThread[1];
  request->OPCODE = 800;  // run a function on the window thread
  request->userFunction = [] {
    while (!closing) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    workDone = true;
  };
  WxSubsystem::pushPendingWxRequest(request);
}

/// A death test's child: opens a viewer, keeps the window thread busy, closes the viewer,
/// tries a second one, then exits normally.
[[noreturn]] void openCloseAndExit(const std::string& display) {
  setenv("DISPLAY", display.c_str(), 1);  // in the child only
  std::atexit(reportAtTheEnd);
  {
    LiveViewer viewer(std::make_shared<KeyframeGraph>());
    keepTheWindowThreadBusy();
    closing = true;
  }
  // Checked the moment the viewer is gone: nothing is left to wait for.
  afterTheViewer = std::string("after the viewer: work ") + (workDone ? "done" : "not done") +
                   ", window thread " + (windowThreadRuns() ? "still running" : "ended");
  // MRPT cannot start its window thread again: a second viewer is refused with the reason.
  try {
    LiveViewer again(std::make_shared<KeyframeGraph>());
    afterTheViewer += "; a second viewer opened";
  } catch (const std::runtime_error& e) {
    afterTheViewer += std::string("; second viewer refused: ") + e.what();
  }
  std::exit(0);
}

}  // namespace

TEST(LiveViewer, TheLastViewerEndsTheWindowThreadHoweverLongItIsBusy) {
  const std::string dir = test::scratchDir("LiveViewer_Exit");
  REQUIRE_VIRTUAL_DISPLAY(display, dir);
  EXPECT_EXIT(openCloseAndExit(display.name()), testing::ExitedWithCode(0),
              "after the viewer: work done, window thread ended; second viewer refused: .*"
              "cannot start it again.*; at the exit: window thread ended");
}
