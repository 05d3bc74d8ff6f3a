// See MrptWindowThread.h. Includes wxWidgets' headers only because MRPT's WxSubsystem.h does;
// everything here goes through MRPT's request queue.

#include "MrptWindowThread.h"

#include <mrpt/gui/CDisplayWindow3D.h>
#include <mrpt/gui/WxSubsystem.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace slamdunk::viewer::window_thread {

namespace {

using mrpt::gui::WxSubsystem;
using Clock = std::chrono::steady_clock;
using Request = WxSubsystem::TRequestToWxMainThread;

// MRPT's request codes (WxSubsystem::CWXMainFrame::OnTimerProcessRequests).
constexpr int kCloseWindow3D = 399;  ///< what ~CDisplayWindow3D asks
constexpr int kRunFunction = 800;
constexpr int kStopThread = 999;  ///< closes the hidden main frame: the loop ends with no window

/// Requests go in MRPT's queue allocated as it requires (new[1]; it frees them).
void post(int opcode, mrpt::gui::CDisplayWindow3D* window = nullptr, std::function<void()> f = {}) {
  auto* request = new Request[1];
  request->OPCODE = opcode;
  request->source3D = window;
  request->userFunction = std::move(f);
  WxSubsystem::pushPendingWxRequest(request);
}

/// MRPT windows open in the process (its count is private; these calls change it and back).
int openWindows() {
  const int withOneMore = WxSubsystem::CWXMainFrame::notifyWindowCreation();
  WxSubsystem::CWXMainFrame::notifyWindowDestruction();
  return withOneMore - 1;
}

struct ExitState {
  std::mutex mutex;
  bool armed = false;    ///< this process's exit (or last user) ends the thread: see armExit
  bool stopped = false;  ///< the thread was stopped and joined
  int users = 0;         ///< start() calls not finished yet
  double seconds = 0;
  std::future<void> threadEnded;            ///< MRPT signals it when its thread has left wxWidgets
  std::vector<std::shared_ptr<void>> kept;  ///< never freed (see keepToTheEnd)
};
ExitState& exitState() {
  static ExitState* state = new ExitState;  // never destroyed: used by the exit handler
  return *state;
}

/// Stops the thread and waits for it to end (up to `seconds`), then joins it; `s.mutex` held.
/// True if it has ended.
bool stopThread(ExitState& s, double seconds) {
  if (s.stopped) return true;
  if (!s.armed) return false;  // not ours to end
  const bool asked = s.threadEnded.wait_for(std::chrono::seconds(0)) == std::future_status::ready ||
                     !WxSubsystem::CWXMainFrame::oneInstance;  // ending already
  if (!asked) {
    // A window closes on the thread (the close is an event, which also updates MRPT's window
    // count): once a function queued after it has run, every close asked before is done.
    if (!run([] {}, seconds)) {
      std::fprintf(stderr, "slamdunk viewer: MRPT's window thread did not answer within %.0f s\n",
                   seconds);
      return false;
    }
    // A window someone else opened keeps the loop running whatever is asked: its owner's (or
    // MRPT's) exit then ends it.
    if (openWindows() > 0) return false;
    post(kStopThread);
  }
  if (s.threadEnded.wait_for(std::chrono::duration<double>(seconds)) != std::future_status::ready) {
    std::fprintf(stderr, "slamdunk viewer: MRPT's window thread did not end within %.0f s\n",
                 seconds);
    return false;
  }
  auto& thread = WxSubsystem::GetWxMainThreadInstance();
  {
    std::lock_guard threadLock(thread.m_csWxMainThreadId);
    if (thread.m_wxMainThreadId.joinable()) thread.m_wxMainThreadId.join();
  }
  s.stopped = true;
  return true;
}

/// The exit's last resort, for a thread that finish() did not stop (a viewer still open at the
/// exit, or another window open when the last viewer ended). It runs after the destructors of
/// the static objects made after armExit (see MrptWindowThread.h): viewers must end before.
void stopAtExit() {
  ExitState& s = exitState();
  std::lock_guard lock(s.mutex);
  stopThread(s, s.seconds);
}

void armExit(double seconds) {
  ExitState& s = exitState();
  std::lock_guard lock(s.mutex);
  // In an application that runs wxWidgets itself, MRPT's windows live in its loop: its exit.
  if (s.armed || !WxSubsystem::isConsoleApp()) return;
  try {
    // MRPT sets this promise but never reads it in this build: the future is ours to take.
    s.threadEnded = WxSubsystem::GetWxMainThreadInstance().m_done.get_future();
  } catch (const std::future_error&) {
    return;  // someone else waits for the thread's end: the exit is theirs
  }
  s.armed = true;
  s.seconds = seconds;
  std::atexit(stopAtExit);
}

}  // namespace

bool start(double seconds) {
  {
    ExitState& s = exitState();
    std::lock_guard lock(s.mutex);
    if (s.stopped)
      throw std::runtime_error(
          "MRPT's window thread ended with the last viewer of this process, and MRPT cannot "
          "start it again: open a process's viewers before its last one closes");
  }
  // MRPT's request queue and window count are a static object made at their first use (by
  // the thread's first timer tick, or the first request): made here, before the exit handler
  // is registered, it is destroyed after the handler has used it.
  openWindows();
  if (!WxSubsystem::CWXMainFrame::oneInstance) {
    // Returns false after MRPT's own 5 s when the thread is slow to start; it starts anyway.
    WxSubsystem::createOneInstanceMainThread();
    if (!waitUntil(seconds, [] { return WxSubsystem::CWXMainFrame::oneInstance != nullptr; }))
      return false;
  }
  armExit(seconds);
  ExitState& s = exitState();
  std::lock_guard lock(s.mutex);
  ++s.users;
  return true;
}

bool finish(double seconds) {
  ExitState& s = exitState();
  std::lock_guard lock(s.mutex);
  if (s.users > 0) --s.users;
  if (s.users > 0) return false;
  return stopThread(s, seconds);
}

bool run(std::function<void()> f, double seconds) {
  auto done = std::make_shared<std::atomic<bool>>(false);
  post(kRunFunction, nullptr, [f = std::move(f), done] {
    f();
    *done = true;
  });
  return waitUntil(seconds, [&] { return done->load(); });
}

bool close(mrpt::gui::CDisplayWindow3D& window, double seconds) {
  if (!window.isOpen()) return true;
  post(kCloseWindow3D, &window);
  return waitUntil(seconds, [&] { return !window.isOpen(); });
}

bool waitUntil(double seconds, const std::function<bool()>& done) {
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (Clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

void keepToTheEnd(std::shared_ptr<void> object) {
  ExitState& s = exitState();
  std::lock_guard lock(s.mutex);
  s.kept.push_back(std::move(object));
}

}  // namespace slamdunk::viewer::window_thread
