// slamdunk-live: SlamDunk on a live RGB-D stream. Frames come from a camera (any MRPT
// CGenericSensor, e.g. COpenNI2Sensor over OpenNI2) or from a rawlog replayed in real time;
// grabbing, tracking and local optimization run in their own threads. On the end of the
// stream, Ctrl-C or SIGTERM it finishes the pipeline and writes every output.

#include "FrameSource.h"
#include "LiveFrameLog.h"
#include "LiveOptions.h"
#include "LivePipeline.h"
#include "LiveSummary.h"
#include "RawlogRecorder.h"
#include "StatusPrinter.h"

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/CommandLine.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/slam/SlamSystem.h>
#ifdef SLAMDUNK_LIVE_WITH_MAPS
#include <slamdunk/maps/CKeyframeGraphMap.h>
#endif
#ifdef SLAMDUNK_LIVE_WITH_RENDER
#include <slamdunk/dense/MapRenderer.h>
#endif

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using namespace slamdunk;
using namespace slamdunk::live;

namespace {

// Set by SIGINT/SIGTERM; the handler does nothing else (only lock-free atomics are safe there).
std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);
extern "C" void onSignal(int) { g_interrupted = true; }

std::string keyframePathFor(const std::string& trajectoryPath) {
  const fs::path p(trajectoryPath);
  return (p.parent_path() / (p.stem().string() + "_keyframes" + p.extension().string())).string();
}

/// A live session cannot be repeated: every output that can be written is (each atomically, so
/// one that fails keeps its earlier version), and the failures are reported at the end.
class OutputAttempts {
 public:
  template <class Write>
  void attempt(const std::string& target, Write write) {
    try {
      write();
    } catch (const std::exception& e) {
      failures_.push_back(writeErrorMessage(target, e.what()));
    }
  }
  const std::vector<std::string>& failures() const { return failures_; }

 private:
  std::vector<std::string> failures_;
};

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
        "pipeline is finished and every output written; exit code 0. See "
        "config-ini/live-openni2.ini and config-ini/live-replay.ini.",
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
    TCLAP::ValueArg<std::string> argGt("g", "gt", "ground truth (TUM file): print ATE at the end",
                                       false, "", "GT.txt", cmd);
    TCLAP::ValueArg<std::string> argFrameLog(
        "", "frame-log",
        "write one CSV line per processed frame (grab time, latency from grab to pose, "
        "tracking ms, state, keyframes)",
        false, "", "FRAMES.csv", cmd);
    TCLAP::SwitchArg argJson("", "json", "print the summary as JSON on stdout", cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "no status lines", cmd);
    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "slamdunk-live")) return *exitCode;

    const auto wallStart = std::chrono::steady_clock::now();
    const LiveOptions options = LiveOptions::fromFile(argConfig.getValue());
    for (const std::string& out :
         {argTraj.getValue(), argKf.getValue(), argMap.getValue(), argRender.getValue(),
          argRecord.getValue(), argFrameLog.getValue()})
      if (!out.empty()) requireWritableFolder(out);
#ifndef SLAMDUNK_LIVE_WITH_MAPS
    if (argMap.isSet())
      throw std::runtime_error("--map: this build has no map module (slamdunk::maps)");
#endif
#ifndef SLAMDUNK_LIVE_WITH_RENDER
    if (argRender.isSet())
      throw std::runtime_error("--render: this build has no map renderer (slamdunk::dense)");
#endif
    Trajectory groundTruth;
    if (argGt.isSet()) groundTruth = readTumTrajectory(argGt.getValue());

    SourceOverrides overrides;
    if (argRawlog.isSet()) overrides.rawlog = argRawlog.getValue();
    if (argSpeed.isSet()) overrides.speed = argSpeed.getValue();
    const auto source = makeFrameSource(*options.config, options.sourceSection, options.iniDir,
                                        overrides, options.frameTimeout);
    std::unique_ptr<RawlogRecorder> recorder;
    if (argRecord.isSet()) recorder = std::make_unique<RawlogRecorder>(argRecord.getValue());
    std::unique_ptr<LiveFrameLog> frameLog;
    if (argFrameLog.isSet()) frameLog = std::make_unique<LiveFrameLog>(argFrameLog.getValue());

    const bool quiet = argQuiet.getValue();
    if (!quiet) std::fprintf(stderr, "[slamdunk-live] source: %s\n", source->describe().c_str());

    SlamSystem slam(options.slam);
    auto pipeline = std::make_unique<LivePipeline>(*source, slam, options.queueCapacity,
                                                   recorder.get(), argMax.getValue());
    pipeline->setFrameLog(frameLog.get());
    pipeline->start();
    if (!pipeline->waitUntilOpen(options.openTimeout, g_interrupted)) {
      if (g_interrupted) abandon("interrupted while opening the source", 130);
      abandon("the source did not open within " + std::to_string(options.openTimeout) +
                  " s ([slamdunk-live] open_timeout): " + source->describe(),
              1);
    }
    StatusPrinter status(quiet ? 0.0 : options.statusPeriod);
    bool stopping = false;
    while (!pipeline->finished()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (g_interrupted && !stopping) {
        stopping = true;
        pipeline->requestStop();
        if (!quiet)
          std::fprintf(stderr, "[slamdunk-live] stopping: finishing the frames received...\n");
      }
      status.tick(pipeline->counters());
    }
    pipeline->join();

    LiveFigures fig;
    fig.counters = pipeline->counters();
    fig.sourceError = pipeline->error();
    fig.latenciesMs = pipeline->latenciesMs();
    fig.interrupted = stopping;
    pipeline.reset();
    if (fig.counters.processed == 0 && !fig.sourceError.empty())
      throw std::runtime_error(fig.sourceError);
    if (fig.counters.processed == 0 && !stopping)
      throw std::runtime_error("the source delivered no RGB-D frame: " + source->describe());

    if (!quiet) std::fprintf(stderr, "[slamdunk-live] finishing the optimization...\n");
    slam.finish();
    fig.stats = slam.statistics();
    fig.mapMemory = slam.graph()->memory();
    const Trajectory traj = slam.trajectory();
    const std::string what = "slamdunk-live " + source->describe();
    OutputAttempts outputs;
    outputs.attempt(argTraj.getValue(), [&] {
      writeTumTrajectory(argTraj.getValue(), traj, what + ": every tracked frame");
    });
    const std::string kfPath =
        argKf.isSet() ? argKf.getValue() : keyframePathFor(argTraj.getValue());
    outputs.attempt(kfPath, [&] {
      writeTumTrajectory(kfPath, slam.keyframeTrajectory(), what + ": keyframes");
    });
#ifdef SLAMDUNK_LIVE_WITH_MAPS
    if (argMap.isSet())
      outputs.attempt(argMap.getValue(),
                      [&] { CKeyframeGraphMap(slam.graph()).saveToFile(argMap.getValue()); });
#endif
    if (recorder) {
      outputs.attempt(argRecord.getValue(), [&] { recorder->finish(); });
      fig.recorded = recorder->written();
      fig.recordSkipped = recorder->skipped();
    }
    if (frameLog) outputs.attempt(argFrameLog.getValue(), [&] { frameLog->finish(); });
#ifdef SLAMDUNK_LIVE_WITH_RENDER
    // Last: the picture is a convenience, the files above are the results.
    if (argRender.isSet())
      outputs.attempt(argRender.getValue(),
                      [&] { renderKeyframeGraph(*slam.graph(), traj, argRender.getValue()); });
#endif
    if (!groundTruth.empty() && traj.size() >= 3) {
      const auto ev = eval::TrajectoryMetrics::evaluate(groundTruth, traj);
      fig.ate = LiveAte{ev.ate.stats.rmse, ev.ate.stats.mean, ev.ate.stats.median, ev.ate.stats.max,
                        ev.pairs};
    } else if (!groundTruth.empty()) {
      std::fprintf(stderr, "slamdunk-live: only %zu tracked frames: no ATE\n", traj.size());
    }
    fig.wallSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    printLiveSummary(fig, argJson.getValue());
    if (!fig.sourceError.empty())
      std::fprintf(stderr, "slamdunk-live: error: %s; the outputs cover the %zu frames before it\n",
                   fig.sourceError.c_str(), fig.counters.processed);
    for (const std::string& failure : outputs.failures())
      std::fprintf(stderr, "slamdunk-live: error: %s\n", failure.c_str());
    if (!outputs.failures().empty()) return 1;
    return fig.sourceError.empty() ? 0 : 2;
  } catch (const TCLAP::ArgException& e) {
    std::cerr << "slamdunk-live: " << e.error() << " (" << e.argId() << "); see --help\n";
  } catch (const std::exception& e) {
    std::cerr << "slamdunk-live: error: " << e.what() << "\n";
  }
  return 1;
}
