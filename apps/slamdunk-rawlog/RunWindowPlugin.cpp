// slamdunk-rawlog-gui.so: the --gui window of slamdunk-rawlog (see RunWindow.h), over the live
// viewer (slamdunk::viewer).

#include "RunWindow.h"

#include <slamdunk/viewer/LiveViewer.h>

#include <cstdio>
#include <filesystem>

namespace slamdunk {
namespace {

class ViewerWindow : public RunWindowBackend {
 public:
  ViewerWindow(apps::RawlogSlamRun& run, bool paused, std::function<void(const std::string&)> log)
      : viewer_(run.graph(), options(run)) {
    if (paused) viewer_.playback().togglePause();
    run.beforeFrame([this, log](size_t framesDone) {
      if (viewer_.playback().paused() && log)
        log("[slamdunk-rawlog] paused before frame " + std::to_string(framesDone));
      viewer_.waitWhilePaused();
    });
    run.onFrame([this](const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult& r) {
      viewer_.publish(obs, r);
    });
  }

  void flush() override { viewer_.flush(); }

  void waitUntilClosed() override {
    if (!viewer_.isOpen()) return;
    std::fprintf(stderr, "[slamdunk-rawlog] close the viewer window (or press q in it) to exit\n");
    viewer_.waitUntilClosed();
  }

 private:
  static viewer::ViewerOptions options(const apps::RawlogSlamRun& run) {
    viewer::ViewerOptions view;
    view.title = "SlamDunk - " + std::filesystem::path(run.options().rawlog).filename().string();
    view.playbackKeys = true;
    return view;
  }

  viewer::LiveViewer viewer_;
};

}  // namespace
}  // namespace slamdunk

extern "C" slamdunk::RunWindowBackend* slamdunkOpenRunWindow(
    slamdunk::apps::RawlogSlamRun& run, bool paused, std::function<void(const std::string&)> log) {
  return new slamdunk::ViewerWindow(run, paused, std::move(log));
}
