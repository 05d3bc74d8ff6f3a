#include <slamdunk/viewer/LiveViewer.h>

#include "MrptWindowThread.h"

#include <mrpt/gui/CDisplayWindow3D.h>
#include <mrpt/gui/keycodes.h>
#include <mrpt/system/CObserver.h>

#include <X11/Xlib.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace slamdunk::viewer {

namespace {

using Clock = std::chrono::steady_clock;

/// How long closing waits for the idle-priority window thread to handle its last requests
/// (see closeWindow()): far beyond any starvation seen under load, short of a hang.
constexpr double kWindowThreadAnswerSeconds = 300;

/// MRPT's window system does not report a missing display: it waits, prints a timeout and
/// goes on with a window that never shows. Ask X first and say what to do.
void requireDisplay() {
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name)
    throw std::runtime_error(
        "the viewer needs an X display and DISPLAY is not set (without a screen, run it under "
        "a virtual one: xvfb-run -a ...)");
  Display* display = XOpenDisplay(nullptr);
  if (!display)
    throw std::runtime_error(std::string("the viewer cannot open the X display '") + name +
                             "' (is the X server running, and may this user use it?)");
  XCloseDisplay(display);
}

/// Linux applies a nice value to the calling thread alone, and the threads it starts inherit
/// it.
void setThreadNiceness(int niceness) {
  setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), niceness);
}

/// CPU seconds used so far by this process's threads under the SCHED_IDLE policy: the drawing
/// threads (MRPT's window thread and the software renderer's, see openWindow()). Read from
/// /proc/self/task/*/stat: utime and stime (fields 14, 15) and the policy (field 41).
double drawingCpuSeconds() {
  static const double ticksPerSecond = static_cast<double>(sysconf(_SC_CLK_TCK));
  double seconds = 0;
  std::error_code ec;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    std::ifstream in(task.path() / "stat");
    std::string line;
    if (!std::getline(in, line)) continue;
    const size_t afterName = line.rfind(')');  // the thread's name may hold spaces
    if (afterName == std::string::npos) continue;
    std::istringstream fields(line.substr(afterName + 1));
    std::vector<std::string> f{std::istream_iterator<std::string>(fields), {}};
    // f[0] is field 3 (state): field n is f[n - 3].
    if (f.size() < 39 || f[38] != std::to_string(SCHED_IDLE)) continue;
    seconds += (std::stod(f[11]) + std::stod(f[12])) / ticksPerSecond;
  }
  return seconds;
}

double secondsSinceStart() {
  static const auto start = Clock::now();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

/// Every key pressed in the window, in order. The window itself keeps only the last one, and
/// keys typed faster than the viewer polls (a key-repeat, a script) would be lost; its events
/// are not (they arrive on the window's thread).
class LiveViewer::KeyQueue : public mrpt::system::CObserver {
 public:
  std::deque<int> take() {
    std::lock_guard lock(mutex_);
    std::deque<int> keys;
    keys.swap(keys_);
    return keys;
  }

 protected:
  void OnEvent(const mrpt::system::mrptEvent& e) override {
    if (const auto* key = dynamic_cast<const mrpt::gui::mrptEventWindowChar*>(&e)) {
      std::lock_guard lock(mutex_);
      keys_.push_back(key->char_code);
    }
  }

 private:
  std::mutex mutex_;
  std::deque<int> keys_;
};

void LiveViewer::Batch::mergeInto(Batch& older) {
  if (latest) older.latest = std::move(latest);
  older.frames.insert(older.frames.end(), frames.begin(), frames.end());
  older.keyframeColours.insert(older.keyframeColours.end(), keyframeColours.begin(),
                               keyframeColours.end());
  older.loopClosures.insert(older.loopClosures.end(), loopClosures.begin(), loopClosures.end());
  older.status = status;
  latest.reset();
  frames.clear();
  keyframeColours.clear();
  loopClosures.clear();
}

LiveViewer::LiveViewer(std::shared_ptr<const KeyframeGraph> graph, ViewerOptions options)
    : graph_(std::move(graph)), options_(std::move(options)) {
  if (!graph_) throw std::invalid_argument("LiveViewer: no graph");
  requireDisplay();
  thread_ = std::thread([this] { run(); });
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return started_ || !startError_.empty(); });
  if (!startError_.empty()) {
    lock.unlock();
    thread_.join();
    throw std::runtime_error("the viewer window could not be created: " + startError_);
  }
}

LiveViewer::~LiveViewer() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  playback_.release();
  if (thread_.joinable()) thread_.join();
}

void LiveViewer::publish(const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult& r,
                         size_t dropped) {
  if (closed_) return;
  // Everything is gathered in the outbox, which only this thread touches.
  Batch& b = outbox_;
  ViewerStatus& s = b.status;
  // The image is shared (reference-counted), never copied here: the viewer reads it later,
  // and the observation may be unloaded or freed meanwhile without harm.
  const cv::Mat colour = obs.hasIntensityImage ? obs.intensityImage.asCvMatRef() : cv::Mat();
  ViewerFrame f;
  f.index = s.frames;
  f.timestamp = r.timestamp;
  f.status = r.status;
  f.pose = r.pose;
  f.colour = colour;
  f.inliers = r.inlierPixels;
  f.rejected = r.rejectedPixels;
  b.latest = std::move(f);
  b.frames.push_back({r.timestamp, r.status, r.reference, r.poseInReference});
  if (r.newKeyframe) b.keyframeColours.emplace_back(r.keyframeId, colour);
  if (r.loopClosure) {
    b.loopClosures.push_back(r.keyframeId);
    ++s.loopClosures;
  }
  ++s.frames;
  if (r.status == TrackingStatus::Lost) ++s.lost;
  s.keyframes = graph_->keyframeCount();
  s.dropped = dropped;
  const double now = secondsSinceStart();
  rate_.emplace_back(now, s.frames);
  while (rate_.size() > 2 && now - rate_.front().first > 2.0) rate_.pop_front();
  const double span = now - rate_.front().first;
  s.fps = span > 0 ? (s.frames - rate_.front().second) / span : 0;

  // Never wait for the viewer: if it holds the lock (it is taking the previous batch), this
  // frame's data waits in the outbox and goes with the next frame's.
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  b.mergeInto(inbox_);
  fresh_ = true;
}

void LiveViewer::flush() {
  std::unique_lock lock(mutex_);
  if (closed_) return;
  // Called by the publishing thread, or after it ended: what publish() could not hand over
  // goes now.
  outbox_.mergeInto(inbox_);
  fresh_ = true;
  flushRequested_ = true;
  wake_.notify_all();
  changed_.wait(lock, [&] { return !flushRequested_ || closed_; });
}

void LiveViewer::waitUntilClosed() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return closed_.load(); });
}

void LiveViewer::openWindow() {
  // The window thread MRPT starts with the first window, and the renderer's threads it starts
  // in turn, inherit the priority (nice value and policy) of the thread that creates the
  // window: a short-lived helper at the drawing priority, so the viewer's own thread keeps its
  // (higher) one — a thread cannot raise its priority again without privileges.
  std::string error;
  std::thread([&] {
    setThreadNiceness(19);
    if (options_.drawAtIdlePriority) {
      sched_param none{};
      none.sched_priority = 0;
      pthread_setschedparam(pthread_self(), SCHED_IDLE, &none);  // allowed to any user
    }
    try {
      // Started here, not by the window, so that MRPT's 5 s deadline for it does not decide.
      if (!window_thread::start(kWindowThreadAnswerSeconds))
        throw std::runtime_error("MRPT's window thread did not start");
      usesWindowThread_ = true;
      window_ = std::make_unique<mrpt::gui::CDisplayWindow3D>(options_.title, options_.width,
                                                              options_.height);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }).join();
  if (!error.empty()) throw std::runtime_error(error);
  // MRPT stops waiting for the window after 6 s; its request stays queued, and a window thread
  // at the idle priority on a busy machine may take longer.
  const auto isOpen = [&] { return window_->isOpen(); };
  if (!window_thread::waitUntil(kWindowThreadAnswerSeconds, isOpen))
    throw std::runtime_error("MRPT's window thread did not open the window");
  keys_ = std::make_unique<KeyQueue>();
  // The window publishes its events on its thread, to a list of observers that has no lock:
  // joined on that thread.
  if (!window_thread::run(
          [keys = keys_.get(), window = window_.get()] { keys->observeBegin(*window); },
          kWindowThreadAnswerSeconds))
    throw std::runtime_error("MRPT's window thread did not answer");
  LiveMapSceneOptions sceneOptions = options_.scene;
  sceneOptions.windowAspect = double(options_.width) / options_.height;
  scene_ = std::make_unique<LiveMapScene>(sceneOptions);
  {
    mrpt::opengl::COpenGLScene::Ptr scene;
    mrpt::gui::CDisplayWindow3DLocker locked(*window_, scene);
    scene_->attachTo(*scene);
  }
  window_->setCameraZoom(6.0f);
  window_->setCameraElevationDeg(40.0f);
  window_->setCameraAzimuthDeg(200.0f);  // behind the first camera, which looks along +x
  window_->forceRepaint();
}

void LiveViewer::run() {
  setThreadNiceness(options_.niceness);
  try {
    openWindow();
  } catch (const std::exception& e) {
    closeWindow();  // what was made so far
    endWindowThread();
    std::lock_guard lock(mutex_);
    startError_ = e.what();
    changed_.notify_all();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    started_ = true;
  }
  changed_.notify_all();

  // The pace: at most maxFps updates a second, and fewer when drawing one costs more than the
  // share of a core it may take (maxDrawingCpu). Idle-priority drawing still slows SLAM on a
  // small machine (shared caches; a 2-core VM: 10 updates a second at 34 ms of CPU each made
  // tracking's p95 17 % longer), so its cost is measured, not assumed.
  const double minPeriod = 1.0 / std::max(0.1, options_.maxFps);
  double drawCostPerUpdate = 0, cpuAtLastUpdate = drawingCpuSeconds();
  bool measuredOnce = false;
  auto nextUpdate = Clock::now();
  bool wasPaused = false;
  for (;;) {
    bool flush, fresh;
    {
      std::unique_lock lock(mutex_);
      // Short naps: keys and the window's close button are polled, not signalled.
      wake_.wait_for(lock, std::chrono::milliseconds(30),
                     [&] { return stopping_ || flushRequested_; });
      if (stopping_) break;
      flush = flushRequested_;
      fresh = fresh_;
    }
    if (!window_->isOpen() || !handleKeys()) break;
    const bool paused = playback_.paused();
    if ((fresh || paused != wasPaused || flush) && (flush || Clock::now() >= nextUpdate)) {
      wasPaused = paused;
      try {
        update();
      } catch (const std::exception& e) {
        // A display problem must not end the SLAM run: the viewer closes, with the reason.
        std::fprintf(stderr, "slamdunk viewer: closed after an error: %s\n", e.what());
        break;
      }
      // The CPU drawn since the last update is mostly the repaint the previous one asked for.
      const double cpu = drawingCpuSeconds();
      const double cost = cpu - cpuAtLastUpdate;
      cpuAtLastUpdate = cpu;
      drawCostPerUpdate = measuredOnce ? 0.7 * drawCostPerUpdate + 0.3 * cost : cost;
      measuredOnce = true;
      double period = minPeriod;
      if (options_.maxDrawingCpu > 0)
        period = std::clamp(drawCostPerUpdate / options_.maxDrawingCpu, minPeriod, 2.0);
      nextUpdate = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(period));
    }
    if (flush) {
      std::lock_guard lock(mutex_);
      flushRequested_ = false;
      changed_.notify_all();
    }
  }
  closeWindow();
  playback_.release();
  endWindowThread();
  std::lock_guard lock(mutex_);
  closed_ = true;
  flushRequested_ = false;
  changed_.notify_all();
}

void LiveViewer::endWindowThread() {
  // The last viewer of the process stops MRPT's window thread and joins it here, while every
  // object it uses still lives, rather than leaving it to the process's exit: see
  // MrptWindowThread.h (the double free at the exit of slamdunk-live --gui --gui-wait).
  // It goes on while another viewer or window is open (then the last viewer or the exit stops
  // it), or if it does not answer (finish() says so).
  if (usesWindowThread_) window_thread::finish(kWindowThreadAnswerSeconds);
  usesWindowThread_ = false;
}

bool LiveViewer::handleKeys() {
  for (const int key : keys_->take()) {
    if (key == 'q' || key == 'Q' || key == mrpt::gui::MRPTK_ESCAPE) return false;
    if (!options_.playbackKeys) continue;
    if (key == ' ')
      playback_.togglePause();
    else if (key == 's' || key == 'S' || key == mrpt::gui::MRPTK_RIGHT)
      playback_.step();
  }
  return true;
}

void LiveViewer::update() {
  Batch batch;
  {
    std::lock_guard lock(mutex_);
    inbox_.mergeInto(batch);
    fresh_ = false;
  }
  if (batch.latest) shown_ = std::move(batch.latest);
  if (options_.playbackKeys)
    batch.status.note = playback_.paused()
                            ? "PAUSED   space: run   s / right arrow: one frame   q: close"
                            : "space: pause   s / right arrow: one frame   q: close";
  for (const auto& f : batch.frames) scene_->addFrame(f);
  for (const auto& [id, image] : batch.keyframeColours) scene_->setKeyframeColour(id, image);
  for (KeyframeId id : batch.loopClosures) scene_->markLoopClosure(id);
  // The window draws from the scene on its own thread: the scene changes under its lock.
  {
    mrpt::opengl::COpenGLScene::Ptr scene;
    mrpt::gui::CDisplayWindow3DLocker locked(*window_, scene);
    scene_->update(*graph_, shown_ ? &*shown_ : nullptr, batch.status);
  }
  const Eigen::Vector3d p = scene_->cameraPosition();
  window_->setCameraPointingToPoint(float(p.x()), float(p.y()), float(p.z()));
  window_->forceRepaint();
  ++updates_;
}

void LiveViewer::closeWindow() {
  if (window_ && window_->isOpen()) {
    // Before the close, every request queued so far is let through:
    //  1. the map is hidden, so that the last repaint is cheap even at the idle priority;
    //  2. one last repaint is requested, then a marker function through the same queue: when
    //     it runs, every request before it (our updates' and this repaint's) has been handled;
    //  3. the next picture the window captures after that is the last repaint on the screen.
    // The window thread draws at the idle priority, so while other work fills every core it
    // may not run for many seconds: no deadline that load can reach decides here
    // (LiveViewer.ClosingWaitsForTheWindowThreadHoweverLongItIsBusy).
    if (scene_) {
      mrpt::opengl::COpenGLScene::Ptr scene;
      mrpt::gui::CDisplayWindow3DLocker locked(*window_, scene);
      scene_->hideMap();
    }
    window_->captureImagesStart();
    window_->forceRepaint();
    if (window_thread::run([] {}, kWindowThreadAnswerSeconds)) {
      const auto before = window_->getLastWindowImagePtr();
      window_thread::waitUntil(5, [&] {
        const auto now = window_->getLastWindowImagePtr();
        return now && now != before;
      });
      window_->captureImagesStop();
    }
    // MRPT's own close (the window's destructor) stops waiting after 6 s and frees the window
    // while its close is still queued; this one waits as long as the thread takes.
    if (!window_thread::close(*window_, kWindowThreadAnswerSeconds))
      std::fprintf(stderr,
                   "slamdunk viewer: MRPT's window thread did not close the window in %.0f s\n",
                   kWindowThreadAnswerSeconds);
  }
  // Not freed: events queued before the close may still name the window and its observer
  // (window_thread::keepToTheEnd). The memory kept is the closed window's scene.
  struct ClosedWindow {
    std::unique_ptr<KeyQueue> keys;
    std::unique_ptr<mrpt::gui::CDisplayWindow3D> window;
  };
  if (window_)
    window_thread::keepToTheEnd(
        std::make_shared<ClosedWindow>(ClosedWindow{std::move(keys_), std::move(window_)}));
  keys_.reset();
}

}  // namespace slamdunk::viewer
