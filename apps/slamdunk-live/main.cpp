// slamdunk-live: SlamDunk on a live RGB-D stream, a command line over slamdunk::live::LiveSlam
// (modules/live: sources, threads, recording, checkpoints). Frames come from a camera (any MRPT
// CGenericSensor, e.g. COpenNI2Sensor over OpenNI2) or from a rawlog replayed in real time. On
// the end of the stream, Ctrl-C or SIGTERM it finishes the session and writes every output.

#include "StatusPrinter.h"

#include <slamdunk/apps/LiveSummary.h>
#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/live/LiveSlam.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#ifdef SLAMDUNK_WITH_VIEWER
#include <slamdunk/viewer/LiveViewer.h>
#endif

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

using namespace slamdunk;
using namespace slamdunk::live;

namespace {

// Set by SIGINT/SIGTERM; the handler does nothing else (only lock-free atomics are safe there).
std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);
extern "C" void onSignal(int) { g_interrupted = true; }

/// The grabber thread may be stuck inside a driver call that cannot be cancelled: leave
/// without running destructors (the OS releases the device).
[[noreturn]] void abandon(const std::string& message, int code) {
  std::fprintf(stderr, "slamdunk-live: error: %s\n", message.c_str());
  std::fflush(stderr);
  std::fflush(stdout);
  std::_Exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  // First, so that an interrupt while the INI, ground truth or source are being loaded is not
  // lost (a background job of a non-interactive shell starts with SIGINT ignored).
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    TCLAP::CmdLine cmd(
        "SlamDunk RGB-D SLAM on a live stream: a camera (COpenNI2Sensor or any MRPT "
        "CGenericSensor, configured as in rawlog-grabber) or a rawlog replayed in real time. "
        "Grabbing, tracking and local optimization run concurrently; when tracking falls "
        "behind, the oldest waiting frame is dropped. Stop with Ctrl-C (or SIGTERM): the "
        "pipeline is finished and every output written; exit code 0. Unless the INI turns them "
        "off, checkpoints (trajectory and map so far) are written every few keyframes or "
        "seconds to OUT_checkpoint/, so a killed session loses at most one interval; "
        "--load-map OUT_checkpoint/map.map resumes it. See config-ini/live-openni2.ini and "
        "config-ini/live-replay.ini.",
        ' ', "1.0");
    TCLAP::ValueArg<std::string> argConfig(
        "c", "config", "live INI ([slamdunk-live] + source section)", true, "", "LIVE.ini", cmd);
    TCLAP::ValueArg<std::string> argTraj(
        "t", "trajectory", "output TUM trajectory of all tracked frames", true, "", "OUT.txt", cmd);
    TCLAP::ValueArg<std::string> argKf(
        "k", "keyframes", "output TUM trajectory of the keyframes (default: OUT_keyframes.txt)",
        false, "", "KF.txt", cmd);
    TCLAP::ValueArg<std::string> argMap("m", "map", "output keyframe map (CKeyframeGraphMap)",
                                        false, "", "OUT.map", cmd);
    TCLAP::ValueArg<std::string> argRender("", "render", "output picture of the map (PNG)", false,
                                           "", "OUT.png", cmd);
    TCLAP::ValueArg<std::string> argGridMap(
        "", "gridmap",
        "output 2D occupancy grid a robot navigates on: PREFIX.gridmap (MRPT's "
        "COccupancyGridMap2D), PREFIX.png and PREFIX.yaml (ROS map_server), at the end and in "
        "each checkpoint; resolution and obstacle heights in the pipeline's [grid_map]",
        false, "", "PREFIX", cmd);
    TCLAP::ValueArg<std::string> argRecord(
        "r", "record", "record the received frames to this rawlog (images embedded)", false, "",
        "OUT.rawlog", cmd);
    TCLAP::ValueArg<std::string> argRawlog("", "rawlog",
                                           "replay source: the rawlog to play "
                                           "(overrides the INI)",
                                           false, "", "IN.rawlog", cmd);
    TCLAP::ValueArg<double> argSpeed("", "speed",
                                     "replay source: speed factor (1 = real time; "
                                     "overrides the INI)",
                                     false, 1.0, "X", cmd);
    TCLAP::ValueArg<size_t> argMax("", "max-frames", "stop after receiving N frames (0 = no limit)",
                                   false, 0, "N", cmd);
    TCLAP::ValueArg<std::string> argFrameLog(
        "", "frame-log",
        "output CSV, one line per processed frame: grab time, latency from grab to pose, "
        "tracking ms, state, keyframes",
        false, "", "FRAMES.csv", cmd);
    TCLAP::ValueArg<std::string> argGt("g", "gt", "ground truth (TUM file): print ATE at the end",
                                       false, "", "GT.txt", cmd);
    TCLAP::ValueArg<std::string> argLoadMap(
        "", "load-map",
        "start from a saved map (a --map output or a checkpoint's map.map): the camera "
        "relocalizes in it, then mapping continues (trajectory in the saved map's frame)",
        false, "", "IN.map", cmd);
    TCLAP::SwitchArg argLocalize(
        "", "localize",
        "with --load-map: localization only, the map is not changed (no keyframe is added); the "
        "status line says when the view is outside the mapped area",
        cmd);
    TCLAP::SwitchArg argExtend(
        "", "extend-map",
        "with --localize: where the map covers too little of the view, add keyframes as mapping "
        "does (the loaded keyframes stay as they are)",
        cmd);
    TCLAP::SwitchArg argJson("", "json", "print the summary as JSON on stdout", cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "no status lines", cmd);
    TCLAP::SwitchArg argGui("", "gui",
                            "show the session in a 3D window (map, trajectory, camera, image "
                            "with its features, status); drawn by its own thread, it never "
                            "holds tracking back. q in the window closes it (the session goes on)",
                            cmd);
    TCLAP::SwitchArg argGuiWait("", "gui-wait",
                                "with --gui: keep the window open after the session, until it "
                                "is closed (or q is pressed in it)",
                                cmd);
    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "slamdunk-live")) return *exitCode;

    const auto wallStart = std::chrono::steady_clock::now();
    if (argGuiWait.getValue() && !argGui.getValue())
      throw std::runtime_error("--gui-wait goes with --gui");
#ifndef SLAMDUNK_WITH_VIEWER
    if (argGui.getValue())
      throw std::runtime_error("--gui: this build has no viewer (slamdunk::viewer needs X11)");
#endif
    rejectPathClashes(
        {{"--config", argConfig.getValue()},
         {"--rawlog", argRawlog.getValue()},
         {"--gt", argGt.getValue()},
         {"--load-map", argLoadMap.getValue()}},
        {{"--trajectory", argTraj.getValue()},
         {argKf.isSet() ? "--keyframes" : "the keyframe trajectory",
          argKf.isSet() ? argKf.getValue() : keyframeTrajectoryPathFor(argTraj.getValue())},
         {"--map", argMap.getValue()},
         {"--render", argRender.getValue()},
         {"--gridmap", argGridMap.isSet() ? argGridMap.getValue() + ".gridmap" : ""},
         {"--gridmap", argGridMap.isSet() ? argGridMap.getValue() + ".png" : ""},
         {"--gridmap", argGridMap.isSet() ? argGridMap.getValue() + ".yaml" : ""},
         {"--record", argRecord.getValue()},
         {"--frame-log", argFrameLog.getValue()}});
    if (argRender.isSet()) requireWritableFolder(argRender.getValue());
    Trajectory groundTruth;
    if (argGt.isSet()) groundTruth = readTumTrajectory(argGt.getValue());
    const bool quiet = argQuiet.getValue();

    LiveSession session;
    session.trajectory = argTraj.getValue();
    session.keyframes = argKf.getValue();
    session.map = argMap.getValue();
    session.gridMap = argGridMap.getValue();
    session.recording = argRecord.getValue();
    session.frameLog = argFrameLog.getValue();
    session.maxFrames = argMax.getValue();
    if (argLoadMap.isSet()) {
      session.startMap = CKeyframeGraphMap::loadFromFile(argLoadMap.getValue())->graph();
      if (!quiet)
        std::fprintf(stderr, "[slamdunk-live] loaded map '%s': %zu keyframes, %zu edges\n",
                     argLoadMap.getValue().c_str(), session.startMap->keyframeCount(),
                     session.startMap->edgeCount());
    }
    if (argLocalize.getValue() && !argLoadMap.isSet())
      throw std::runtime_error(
          "localization only (--localize) needs the map to localize in: --load-map IN.map");
    if (argExtend.getValue() && !argLocalize.getValue())
      throw std::runtime_error("--extend-map goes with --localize");
    session.localizationOnly = argLocalize.getValue();
    session.extendMap = argExtend.getValue();
    SourceOverrides overrides;
    if (argRawlog.isSet()) overrides.rawlog = argRawlog.getValue();
    if (argSpeed.isSet()) overrides.speed = argSpeed.getValue();
    const auto live = LiveSlam::fromIniFile(argConfig.getValue(), session, overrides);
    const LiveOptions& options = live->options();
    if (!quiet) {
      std::fprintf(stderr, "[slamdunk-live] source: %s\n", live->source().describe().c_str());
      if (const std::string cp = live->checkpointFolder(); !cp.empty())
        std::fprintf(stderr, "[slamdunk-live] checkpoints: %s\n", cp.c_str());
    }

#ifdef SLAMDUNK_WITH_VIEWER
    // Shared with the tracking thread's callback, so it outlives the session in any case. It
    // ends (and, being the last window, stops MRPT's window thread) when its window is closed,
    // or at the latest with `live` before main returns: never in the process's exit.
    std::shared_ptr<viewer::LiveViewer> gui;
    if (argGui.getValue()) {
      viewer::ViewerOptions view;
      view.title = "SlamDunk live - " + live->source().describe();
      gui = std::make_shared<viewer::LiveViewer>(live->graph(), view);
      LiveSlam& session = *live;
      live->onFrame(
          [gui, &session](const mrpt::obs::CObservation3DRangeScan& obs, const TrackingResult& r) {
            gui->publish(obs, r, session.counters().dropped);
          });
    }
#endif
    live->start();
    if (!live->waitUntilOpen(options.openTimeout, &g_interrupted)) {
      if (g_interrupted) abandon("interrupted while opening the source", 130);
      abandon("the source did not open within " + std::to_string(options.openTimeout) +
                  " s ([slamdunk-live] open_timeout): " + live->source().describe(),
              1);
    }
    StatusPrinter status(quiet ? 0.0 : options.statusPeriod);
    bool stopping = false;
    while (!live->finished()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (g_interrupted && !stopping) {
        stopping = true;
        live->requestStop();
        if (!quiet)
          std::fprintf(stderr, "[slamdunk-live] stopping: finishing the frames received...\n");
      }
      status.tick(live->counters());
      if (!quiet) status.checkpoints(live->checkpointFigures());
    }
    if (!quiet) std::fprintf(stderr, "[slamdunk-live] finishing the optimization...\n");
    apps::LiveFigures fig;
    fig.result = live->finish();
    LiveResult& result = fig.result;
    // Last: the picture is a convenience, the files above are the results. Like them, a
    // failure is reported at the end and keeps the earlier picture.
    if (argRender.isSet()) {
      try {
        renderKeyframeGraph(*result.graph, result.trajectory, argRender.getValue());
      } catch (const std::exception& e) {
        result.outputFailures.push_back(writeErrorMessage(argRender.getValue(), e.what()));
      }
    }
    if (!groundTruth.empty()) {
      fig.ate = apps::evaluateAte(groundTruth, result.trajectory);
      if (!fig.ate)
        std::fprintf(stderr, "slamdunk-live: only %zu tracked frames: no ATE\n",
                     result.trajectory.size());
    }
    fig.wallSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    apps::printLiveSummary(fig, argJson.getValue());
    // Out now: stdout may be a pipe (fully buffered), and the summary must not depend on how
    // the viewer's window and the process end.
    std::fflush(stdout);
#ifdef SLAMDUNK_WITH_VIEWER
    if (gui && argGuiWait.getValue() && gui->isOpen()) {
      gui->flush();
      std::fprintf(stderr, "[slamdunk-live] close the viewer window (or press q in it) to exit\n");
      gui->waitUntilClosed();
    }
#endif
    if (result.checkpoints && !result.checkpoints->error.empty())
      std::fprintf(stderr, "slamdunk-live: warning: a checkpoint failed: %s\n",
                   result.checkpoints->error.c_str());
    if (!result.sourceError.empty())
      std::fprintf(stderr, "slamdunk-live: error: %s; the outputs cover the %zu frames before it\n",
                   result.sourceError.c_str(), result.counters.processed);
    for (const std::string& failure : result.outputFailures)
      std::fprintf(stderr, "slamdunk-live: error: %s\n", failure.c_str());
    if (!result.outputFailures.empty()) return 1;
    return result.sourceError.empty() ? 0 : 2;
  } catch (const TCLAP::ArgException& e) {
    std::cerr << "slamdunk-live: " << e.error() << " (" << e.argId() << "); see --help\n";
  } catch (const std::exception& e) {
    std::cerr << "slamdunk-live: error: " << e.what() << "\n";
  }
  return 1;
}
