#pragma once
// The live 3D viewer: an MRPT window (CDisplayWindow3D) showing the current colour image with
// its features, the keyframe map (cloud, frustums, graph edges, loop closures highlighted), the
// trajectory, the current camera and a status line (see LiveMapScene); the view follows the
// camera, the mouse turns and zooms it as in any MRPT window.
//
// It never holds tracking back: publish() (the tracking thread, after each frame) copies a few
// kilobytes and never waits: when the viewer is busy taking the last batch, the frame goes with
// the next one. The window is updated by the viewer's own thread at most `maxFps` times a second
// from the latest frame published (frames in between are not drawn), and drawn by MRPT's window
// thread and the OpenGL renderer's threads at the idle CPU priority (SCHED_IDLE), so drawing
// only uses the CPU that SLAM leaves; updates are spaced further when drawing costs more than
// `maxDrawingCpu` of a core (idle-priority work still competes for caches). Offline runs can pause
// and step (keys: space, s / right arrow) through waitWhilePaused().
//
//   LiveViewer viewer(slam.graph(), {"SlamDunk"});
//   for each frame: r = slam.process(obs); viewer.publish(obs, r);

#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/tracking/Tracker.h>
#include <slamdunk/viewer/LiveMapScene.h>
#include <slamdunk/viewer/PlaybackControl.h>

#include <mrpt/obs/CObservation3DRangeScan.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace mrpt::gui {
class CDisplayWindow3D;
}

namespace slamdunk::viewer {

struct ViewerOptions {
  std::string title = "SlamDunk";
  int width = 1024, height = 640;  ///< pixels
  double maxFps = 10;              ///< window updates per second, at most
  /// Share of one core the drawing threads may take: updates are spaced so that each one's
  /// measured drawing CPU fits in it (between 1/maxFps and 2 s apart). 0 = no limit. Measured
  /// on the threads at the idle priority, so it applies with drawAtIdlePriority.
  double maxDrawingCpu = 0.1;
  /// Offline: space pauses and resumes, s or the right arrow processes one frame.
  bool playbackKeys = false;
  /// CPU priority (nice) of the viewer's thread, which updates the scene (light work).
  int niceness = 10;
  /// The threads that draw (MRPT's window thread and the software OpenGL renderer's) run under
  /// Linux's SCHED_IDLE policy, below every nice level: they take the CPU that the SLAM
  /// threads — including low-priority helpers such as slamdunk-rawlog's frame decoder at
  /// nice 19 — leave. false: nice 19 only.
  bool drawAtIdlePriority = true;
  LiveMapSceneOptions scene;
};

class LiveViewer {
 public:
  /// Opens the window. Throws std::runtime_error when no X display can be opened (DISPLAY
  /// unset or unreachable) or the window cannot be created (also once the process's window
  /// thread has been stopped, see ~LiveViewer).
  LiveViewer(std::shared_ptr<const KeyframeGraph> graph, ViewerOptions options = {});
  /// Closes the window (unless closed already), once MRPT's window thread has handled every
  /// request before the close however long that takes. The closed window object (and its
  /// scene) is kept to the process's end (src/MrptWindowThread.h says why). When the window
  /// closes — by a key, its close button or this destructor — and no other viewer or MRPT
  /// window is open, MRPT's window thread is stopped and joined (waited for however long it is
  /// busy, up to 300 s), so that the process's exit finds no thread using what it destroys.
  /// MRPT cannot start that thread twice: a viewer opened in the same process after that
  /// throws std::runtime_error. A viewer still open when the process exits is left to an exit
  /// handler, which runs too late to be safe: destroy viewers before main returns.
  ~LiveViewer();
  LiveViewer(const LiveViewer&) = delete;
  LiveViewer& operator=(const LiveViewer&) = delete;

  /// After each frame, from one thread (the tracking thread): hands over what the window
  /// shows (the image shared, not copied) and returns without waiting. `dropped`: frames the
  /// live pipeline dropped so far.
  void publish(const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult& r,
               size_t dropped = 0);
  /// Offline, before each frame: returns at once unless paused (then waits for a key).
  void waitWhilePaused() { playback_.waitForTurn(); }
  PlaybackControl& playback() { return playback_; }

  /// Draws what was published last, now (end of a run). Call it from the thread that
  /// publishes, or after that thread ended.
  void flush();
  bool isOpen() const { return !closed_; }
  /// Blocks until the user closes the window or presses q or Esc in it, and the window is
  /// closed (with MRPT's window thread, if this was the last window: see ~LiveViewer).
  void waitUntilClosed();

  size_t updatesDrawn() const { return updates_; }

 private:
  /// What the tracking thread has published and the viewer has not taken yet.
  struct Batch {
    std::optional<ViewerFrame> latest;
    std::vector<FrameRecord> frames;
    std::vector<std::pair<KeyframeId, cv::Mat>> keyframeColours;
    std::vector<KeyframeId> loopClosures;
    ViewerStatus status;
    void mergeInto(Batch& older);  ///< appends this batch's data to an older one, then clears
  };

  void run();
  void openWindow();
  bool handleKeys();
  void update();
  void closeWindow();
  void endWindowThread();

  const std::shared_ptr<const KeyframeGraph> graph_;
  const ViewerOptions options_;
  PlaybackControl playback_;

  // Tracking thread only: what could not be handed over yet, and the status counters.
  Batch outbox_;
  std::deque<std::pair<double, size_t>> rate_;  ///< (seconds, frames) samples for the fps

  mutable std::mutex mutex_;  // guards inbox_ and the states below
  Batch inbox_;
  bool fresh_ = false;  ///< inbox_ holds something not drawn yet
  bool stopping_ = false, flushRequested_ = false, started_ = false;
  std::string startError_;
  std::condition_variable wake_;     ///< stop or flush requested
  std::condition_variable changed_;  ///< started, flushed, closed

  std::atomic<bool> closed_{false};
  std::atomic<size_t> updates_{0};
  class KeyQueue;
  bool usesWindowThread_ = false;                        ///< viewer thread only
  std::unique_ptr<KeyQueue> keys_;                       ///< filled by the window's thread
  std::unique_ptr<mrpt::gui::CDisplayWindow3D> window_;  ///< viewer thread only
  std::unique_ptr<LiveMapScene> scene_;                  ///< viewer thread only
  std::optional<ViewerFrame> shown_;                     ///< viewer thread only
  std::thread thread_;
};

}  // namespace slamdunk::viewer
