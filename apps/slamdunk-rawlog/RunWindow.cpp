#include "RunWindow.h"

#ifdef SLAMDUNK_WITH_VIEWER
#include <slamdunk/viewer/LiveViewer.h>
#endif

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace slamdunk {

#ifdef SLAMDUNK_WITH_VIEWER

struct RunWindow::Viewer : viewer::LiveViewer {
  using viewer::LiveViewer::LiveViewer;
};

RunWindow::RunWindow(apps::RawlogSlamRun& run, bool paused,
                     std::function<void(const std::string&)> log) {
  viewer::ViewerOptions view;
  view.title = "SlamDunk - " + std::filesystem::path(run.options().rawlog).filename().string();
  view.playbackKeys = true;
  viewer_ = std::make_unique<Viewer>(run.graph(), view);
  if (paused) viewer_->playback().togglePause();
  Viewer& gui = *viewer_;
  run.beforeFrame([&gui, log](size_t framesDone) {
    if (gui.playback().paused() && log)
      log("[slamdunk-rawlog] paused before frame " + std::to_string(framesDone));
    gui.waitWhilePaused();
  });
  run.onFrame([&gui](const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult& r) {
    gui.publish(obs, r);
  });
}

void RunWindow::flush() { viewer_->flush(); }

void RunWindow::waitUntilClosed() {
  if (!viewer_->isOpen()) return;
  std::fprintf(stderr, "[slamdunk-rawlog] close the viewer window (or press q in it) to exit\n");
  viewer_->waitUntilClosed();
}

#else

struct RunWindow::Viewer {};

RunWindow::RunWindow(apps::RawlogSlamRun&, bool, std::function<void(const std::string&)>) {
  throw std::runtime_error("--gui: this build has no viewer (slamdunk::viewer needs X11)");
}

void RunWindow::flush() {}
void RunWindow::waitUntilClosed() {}

#endif

RunWindow::~RunWindow() = default;

}  // namespace slamdunk
