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

#include <functional>
#include <memory>

namespace mrpt::gui {
class CDisplayWindow3D;
}

namespace slamdunk::viewer::window_thread {

/// Starts the window thread (it inherits the calling thread's CPU priority) unless it runs,
/// and arms the exit: at the process's exit, the thread is stopped and waited for (up to
/// `seconds`) before anything it uses is destroyed. False if it has not started in `seconds`.
bool start(double seconds);

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
