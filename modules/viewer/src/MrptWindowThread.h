#pragma once
// MRPT's window thread: the wxWidgets main loop that runs every MRPT window of the process.
// MRPT waits for it with fixed deadlines (5 s for it to start, 6 s for a window to open or to
// close, 100 ms at the process's exit) and, when they pass, goes on as if it had answered: it
// frees a window whose close is still queued, or lets exit destroy wxWidgets' static objects
// under the running loop. Both corrupt the heap ("double free or corruption", "corrupted
// double-linked list" after the last frame; seen in CI and reproduced with the cores kept busy).
// The viewer's window thread draws at the idle CPU priority, so it is slow exactly when the
// machine is busy. These functions take the same steps, wait as long as the caller says, and
// never free what the thread may still use.
//
// The thread is stopped and joined when its last user (a viewer) ends, not at the process's
// exit: exit destroys static objects in the reverse order of their creation, and the window
// system creates many after the thread has started (MRPT's request queue at the first request,
// its texture registry, Mesa's and freeglut's state: on the window thread, during the first
// window's creation and drawing). An exit handler registered when the thread starts runs after
// their destructors, while the thread still uses them: MRPT's request queue was freed before
// the handler pushed its stop request there ("double free or corruption (out)" at the exit of
// `slamdunk-live --gui --gui-wait`, issue 43).

#include <functional>
#include <memory>

namespace mrpt::gui {
class CDisplayWindow3D;
}

namespace slamdunk::viewer::window_thread {

/// Starts the window thread (it inherits the calling thread's CPU priority) unless it runs, and
/// counts the caller as one of its users until its finish(). False if it has not started in
/// `seconds` (nothing to finish then). Throws std::runtime_error once the thread has been
/// stopped (finish() of its last user): MRPT cannot start it again in the same process.
bool start(double seconds);

/// One user of the thread is done with it (its windows are closed). The last one stops the
/// thread and waits (up to `seconds`) for it to end, then joins it, unless windows that someone
/// else opened keep it running: the exit handler armed by start() stops it then. True if the
/// thread has ended.
bool finish(double seconds);

/// Runs `f` on the window thread; false if it has not run within `seconds` (it may still run
/// later: `f` must not refer to anything that dies before the process).
bool run(std::function<void()> f, double seconds);

/// Closes the window, as its destructor would ask; false if it is not closed within `seconds`.
bool close(mrpt::gui::CDisplayWindow3D& window, double seconds);

/// Waits until `done()` (a step of the window thread, polled) or `seconds` pass; true if done.
bool waitUntil(double seconds, const std::function<bool()>& done);

/// Keeps `object` (a closed window, what observes it) to the process's end, never freed: events
/// the thread queued before the close may still name it, and once the thread has ended, its
/// scene's textures can no longer be released (MRPT then spins in releaseTextureID).
void keepToTheEnd(std::shared_ptr<void> object);

}  // namespace slamdunk::viewer::window_thread
