// slamdunk-rawlog: runs SlamDunk over a rawlog of CObservation3DRangeScan and writes the
// trajectory of every tracked frame (TUM format, optical frame) and of the keyframes.

#include "RunSummary.h"

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/PrefetchingRawlogReader.h>
#include <slamdunk/dense/DenseOutputs.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/eval/TrajectoryMetrics.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/slam/SimpleMapExport.h>
#include <slamdunk/slam/SlamSystem.h>
#ifdef SLAMDUNK_WITH_VIEWER
#include <slamdunk/viewer/LiveViewer.h>
#endif

#include <slamdunk/core/CommandLine.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

void writeFrameLogLine(std::ostream& out, size_t index, const TrackingResult& r) {
  char buf[512];
  const Eigen::Vector3d t = r.pose.translation();
  std::snprintf(buf, sizeof(buf),
                "%zu,%.6f,%s,%zu,%zu,%zu,%.3f,%d,%u,%d,%u,%.3f,%.3f,%.3f,%.3f,%.3f,%.5f,%.5f,%.5f,%"
                "zu,%d,%.3f,%d,%d,",
                index, r.timestamp, r.skipped ? "skipped" : toString(r.status), r.features,
                r.matches, r.inliers, r.overlap, r.newKeyframe ? 1 : 0, r.keyframeId,
                r.loopClosure ? 1 : 0, r.reference, r.timings.features, r.timings.pool,
                r.timings.matching, r.timings.ransac, r.timings.total, t.x(), t.y(), t.z(),
                r.poolSize, r.depthOnly ? 1 : 0, r.timings.poolWait, r.relocalized ? 1 : 0,
                r.overlapCells);
  std::string reason = r.lostReason;
  for (char& c : reason)
    if (c == ',') c = ';';
  out << buf << reason << "\n";
}

/// Writes output `target` through `write(stagedPath)`; a failure names the target and why it may
/// have failed (free space, file size limit).
template <class Write>
void writeStaged(const std::string& target, const std::string& staged, Write write) {
  try {
    write(staged);
  } catch (const std::exception& e) {
    throw std::runtime_error(writeErrorMessage(target, e.what(), staged));
  }
}

/// The optional map products of a run, staged with the other outputs.
void writeMapOutputs(StagedOutputs& outputs, const SlamSystem& slam, const Trajectory& traj,
                     const std::string& mapPath, const std::string& densePrefix,
                     const std::string& pngPath, const std::string& simpleMapPath, bool quiet) {
  const KeyframeGraph& graph = *slam.graph();
  if (!mapPath.empty()) {
    writeStaged(mapPath, outputs.stage(mapPath), [&](const std::string& staged) {
      CKeyframeGraphMap(slam.graph()).saveToFile(staged);
    });
  }
  if (!densePrefix.empty()) {
    const std::string staged = outputs.stagePrefix(densePrefix, {".ply", ".pcd", ".ot", ".bt"});
    writeStaged(densePrefix, staged, [&](const std::string&) {
      const auto d = writeDenseOutputs(graph, staged);
      if (!quiet)
        std::fprintf(stderr,
                     "[slamdunk-rawlog] dense cloud of %zu points and OctoMap (%zu "
                     "occupied voxels) for %s.{ply,pcd,ot,bt}\n",
                     d.cloudPoints, d.occupancy.occupiedLeaves, densePrefix.c_str());
    });
  }
  if (!pngPath.empty()) {
    const fs::path png(pngPath);
    const std::string scene = (png.parent_path() / (png.stem().string() + ".3Dscene")).string();
    const std::string stagedPng = outputs.stage(pngPath), stagedScene = outputs.stage(scene);
    writeStaged(pngPath, stagedPng, [&](const std::string&) {
      try {
        renderKeyframeGraph(graph, traj, stagedPng, stagedScene);
      } catch (const std::exception& e) {
        throw std::runtime_error(withTargetName(e.what(), stagedScene, scene));
      }
    });
  }
  if (!simpleMapPath.empty())
    writeStaged(simpleMapPath, outputs.stage(simpleMapPath),
                [&](const std::string& staged) { exportSimpleMap(graph, staged); });
}

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    TCLAP::CmdLine cmd(
        "SlamDunk RGB-D SLAM over a rawlog of CObservation3DRangeScan (camera calibration taken "
        "from the observations). Writes the trajectory of every tracked frame in TUM format "
        "(optical frame, world = first camera), the keyframe trajectory beside it, and prints a "
        "run summary. Lost frames are reported and left out of the trajectory.",
        ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argIn("IN", "input rawlog", true, "", "IN.rawlog", cmd);
    TCLAP::ValueArg<std::string> argConfig(
        "c", "config",
        "pipeline INI (sections [features] [tracker] [optimizer] [slam]); default: "
        "built-in values, the same as config-ini/slamdunk-default.ini",
        false, "", "PIPELINE.ini", cmd);
    TCLAP::ValueArg<std::string> argTraj("t", "trajectory", "output TUM trajectory of all frames",
                                         true, "", "OUT.txt", cmd);
    TCLAP::ValueArg<std::string> argKf(
        "k", "keyframes", "output TUM trajectory of the keyframes (default: OUT_keyframes.txt)",
        false, "", "KF.txt", cmd);
    TCLAP::ValueArg<std::string> argGt("g", "gt", "ground truth (TUM file): print ATE at the end",
                                       false, "", "GT.txt", cmd);
    TCLAP::ValueArg<size_t> argMax("", "max-frames", "process at most N frames (0 = all)", false, 0,
                                   "N", cmd);
    TCLAP::ValueArg<size_t> argFirst("", "first-frame", "skip the frames before this index", false,
                                     0, "I", cmd);
    TCLAP::ValueArg<std::string> argLoadMap(
        "", "load-map",
        "start from a saved map: the camera relocalizes in it, then mapping "
        "continues (trajectory in the saved map's frame)",
        false, "", "IN.map", cmd);
    TCLAP::ValueArg<std::string> argSaveMap(
        "", "save-map",
        "write the keyframe-graph map (slamdunk::CKeyframeGraphMap, readable by "
        "slamdunk-render and by MRPT tools that load libslamdunk_mrpt_map.so)",
        false, "", "OUT.map", cmd);
    TCLAP::SwitchArg argMapImages(
        "", "map-images",
        "keep keyframe colour+depth in the map (needed later for dense "
        "outputs from a saved map; about 0.6 MB per keyframe in the file)",
        cmd);
    TCLAP::ValueArg<std::string> argDense(
        "", "dense",
        "write the dense reconstruction: PREFIX.ply and PREFIX.pcd (voxel-filtered "
        "coloured cloud) and PREFIX.ot / PREFIX.bt (OctoMap)",
        false, "", "PREFIX", cmd);
    TCLAP::ValueArg<std::string> argRender(
        "", "render",
        "render the map (cloud, trajectory, keyframes) offscreen to a PNG; a "
        ".3Dscene for SceneViewer3D is written beside it",
        false, "", "OUT.png", cmd);
    TCLAP::ValueArg<std::string> argSimpleMap(
        "", "simplemap",
        "export keyframe poses + observations as an MRPT .simplemap (for "
        "observations2map and friends)",
        false, "", "OUT.simplemap", cmd);
    TCLAP::ValueArg<std::string> argFrameLog(
        "", "frame-log",
        "write one CSV line per frame (status, features, matches, inliers, "
        "overlap, keyframe, loop closure, ms per stage)",
        false, "", "FRAMES.csv", cmd);
    TCLAP::SwitchArg argJson("", "json", "print the summary as JSON", cmd);
    TCLAP::SwitchArg argNoOpt("", "no-optimization",
                              "disable the local optimization (same as [slam] "
                              "local_optimization=false)",
                              cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "no progress output", cmd);
    TCLAP::SwitchArg argGui(
        "", "gui",
        "show the run in a 3D window (map, trajectory, camera, image with its features, "
        "status); keys in the window: space pauses and resumes, s or the right arrow "
        "processes one frame, q closes the window (the run goes on). Results are the same "
        "with and without it",
        cmd);
    TCLAP::SwitchArg argGuiWait("", "gui-wait",
                                "with --gui: keep the window open after the run, until it is "
                                "closed (or q is pressed in it)",
                                cmd);
    TCLAP::SwitchArg argGuiPaused("", "gui-paused",
                                  "with --gui: start paused (space runs, s or the right arrow "
                                  "processes one frame)",
                                  cmd);
    if (const auto exitCode = slamdunk::parseCommandLine(cmd, argc, argv, "slamdunk-rawlog"))
      return *exitCode;

    if ((argGuiWait.getValue() || argGuiPaused.getValue()) && !argGui.getValue())
      throw std::runtime_error("--gui-wait and --gui-paused go with --gui");
    SlamOptions options;
    if (argConfig.isSet()) options = SlamOptions::fromFile(argConfig.getValue());
    if (argNoOpt.getValue()) options.localOptimization = false;
    if (argMapImages.isSet() || argDense.isSet() || argRender.isSet() || argSimpleMap.isSet())
      options.tracker.keepKeyframeImages = true;
    const std::string kfPath =
        argKf.isSet() ? argKf.getValue() : keyframeTrajectoryPathFor(argTraj.getValue());
    rejectPathClashes({{"IN.rawlog", argIn.getValue()},
                       {"--config", argConfig.getValue()},
                       {"--gt", argGt.getValue()},
                       {"--load-map", argLoadMap.getValue()}},
                      {{"--trajectory", argTraj.getValue()},
                       {argKf.isSet() ? "--keyframes" : "the keyframe trajectory", kfPath},
                       {"--save-map", argSaveMap.getValue()},
                       {"--render", argRender.getValue()},
                       {"--simplemap", argSimpleMap.getValue()},
                       {"--frame-log", argFrameLog.getValue()}});
    // Fail on unwritable outputs before spending minutes on the run.
    for (const std::string& out :
         {argTraj.getValue(), argKf.getValue(), argSaveMap.getValue(), argDense.getValue(),
          argRender.getValue(), argSimpleMap.getValue(), argFrameLog.getValue()})
      if (!out.empty()) requireWritableFolder(out);
    const bool quiet = argQuiet.getValue();
    Trajectory groundTruth;
    if (argGt.isSet()) groundTruth = readTumTrajectory(argGt.getValue());

    // All outputs or none: each is written under a temporary name and they replace the user's
    // files together at the end, so a run that fails on one of them (a full disk, say) leaves
    // every earlier file as it was. A run can be repeated; its files should belong together.
    StagedOutputs outputs;
    std::ofstream frameLog;
    std::string frameLogStaged;
    if (argFrameLog.isSet()) {
      frameLogStaged = outputs.stage(argFrameLog.getValue());
      frameLog.open(frameLogStaged);
      if (!frameLog)
        throw std::runtime_error(
            writeErrorMessage(argFrameLog.getValue(), "cannot create it", frameLogStaged));
      frameLog << "index,timestamp,status,features,matches,inliers,overlap,new_keyframe,"
                  "keyframe_id,loop_closure,reference,ms_features,ms_pool,ms_matching,ms_ransac,"
                  "ms_total,tx,ty,tz,pool_size,depth_only,ms_pool_wait,relocalized,overlap_cells,"
                  "lost_reason\n";
    }
    std::shared_ptr<KeyframeGraph> startMap;
    if (argLoadMap.isSet()) {
      startMap = CKeyframeGraphMap::loadFromFile(argLoadMap.getValue())->graph();
      if (!quiet)
        std::fprintf(stderr, "[slamdunk-rawlog] loaded map '%s': %zu keyframes, %zu edges\n",
                     argLoadMap.getValue().c_str(), startMap->keyframeCount(),
                     startMap->edgeCount());
    }
    // Decoded a few frames ahead on a thread of its own (deterministic: same frames, same order).
    PrefetchingRawlogReader reader(argIn.getValue());
    SlamSystem slam(options, startMap);
#ifdef SLAMDUNK_WITH_VIEWER
    std::unique_ptr<viewer::LiveViewer> gui;
    if (argGui.getValue()) {
      viewer::ViewerOptions view;
      view.title = "SlamDunk - " + fs::path(argIn.getValue()).filename().string();
      view.playbackKeys = true;
      gui = std::make_unique<viewer::LiveViewer>(slam.graph(), view);
      if (argGuiPaused.getValue()) gui->playback().togglePause();
    }
#else
    if (argGui.getValue())
      throw std::runtime_error("--gui: this build has no viewer (slamdunk::viewer needs X11)");
#endif
    double pausedSeconds = 0;  // waiting in the viewer's pause: not part of the run's speed
    RunFigures fig;
    const auto start = std::chrono::steady_clock::now();
    size_t index = 0, skippedWarnings = 0;
    std::string readError;
    for (;;) {
      const auto t = std::chrono::steady_clock::now();
      mrpt::obs::CObservation3DRangeScan::Ptr obs;
      try {
        obs = reader.next();
      } catch (const std::exception& e) {
        // A recording cut short keeps the frames before the damage: they are processed and
        // written, and the exit code still reports the problem.
        readError = e.what();
        break;
      }
      if (!obs) break;
      if (index++ < argFirst.getValue()) continue;
      const double decodeMs = msSince(t);
#ifdef SLAMDUNK_WITH_VIEWER
      if (gui) {
        const auto paused = std::chrono::steady_clock::now();
        if (gui->playback().paused() && !quiet)
          std::fprintf(stderr, "[slamdunk-rawlog] paused before frame %zu\n", fig.decodeMs.size());
        gui->waitWhilePaused();
        pausedSeconds += msSince(paused) / 1000.0;
      }
#endif
      const TrackingResult r = slam.process(*obs);
#ifdef SLAMDUNK_WITH_VIEWER
      if (gui) gui->publish(*obs, r);
#endif
      obs->unload();
      fig.decodeMs.push_back(decodeMs);
      const size_t n = fig.decodeMs.size();
      if (frameLog.is_open()) writeFrameLogLine(frameLog, n - 1, r);
      if (fig.firstTrackedFrame < 0 && r.status != TrackingStatus::Lost)
        fig.firstTrackedFrame = static_cast<long>(n - 1);
      if (r.skipped) {
        // Warned about, a few times: a clock reset can put every later frame behind.
        if (!quiet && ++skippedWarnings <= 10)
          std::fprintf(stderr, "[slamdunk-rawlog] warning: %s%s\n", r.lostReason.c_str(),
                       skippedWarnings == 10 ? " (further such warnings not shown)" : "");
      } else if (!quiet && r.status == TrackingStatus::Lost) {
        std::fprintf(stderr, "frame %zu (t=%.6f): lost: %s\n", n - 1, r.timestamp,
                     r.lostReason.c_str());
      }
      if (!quiet && n % 100 == 0)
        std::fprintf(stderr, "[slamdunk-rawlog] %zu frames, %zu keyframes, %.1f frames/s\n", n,
                     slam.graph()->keyframeCount(), n / (msSince(start) / 1000.0));
      if (argMax.getValue() && n >= argMax.getValue()) break;
    }
    if (!readError.empty() && fig.decodeMs.empty()) throw std::runtime_error(readError);
    if (reader.entriesRead() > 0 && fig.decodeMs.empty())
      throw std::runtime_error(
          "rawlog '" + argIn.getValue() + "' has no CObservation3DRangeScan (" +
          std::to_string(reader.otherObservationsSkipped()) + " other observations)");
    if (fig.decodeMs.empty())
      throw std::runtime_error("rawlog '" + argIn.getValue() + "' is empty");
    slam.finish();
    fig.wallSeconds = msSince(start) / 1000.0 - pausedSeconds;
#ifdef SLAMDUNK_WITH_VIEWER
    if (gui) gui->flush();  // the map after the last optimization
#endif
    fig.stats = slam.statistics();
    fig.edges = slam.graph()->edgeCount();
    fig.mapMemory = slam.graph()->memory();
    fig.peakRssKiB = peakResidentKiB();

    const Trajectory traj = slam.trajectory();
    writeStaged(
        argTraj.getValue(), outputs.stage(argTraj.getValue()), [&](const std::string& staged) {
          writeTumTrajectory(staged, traj,
                             "slamdunk-rawlog " + argIn.getValue() + ": every tracked frame");
        });
    writeStaged(kfPath, outputs.stage(kfPath), [&](const std::string& staged) {
      writeTumTrajectory(staged, slam.keyframeTrajectory(),
                         "slamdunk-rawlog " + argIn.getValue() + ": keyframes");
    });

    if (!groundTruth.empty()) {
      if (traj.size() < 3) {
        std::fprintf(stderr, "slamdunk-rawlog: only %zu tracked frames: no ATE\n", traj.size());
      } else {
        const auto ev = eval::TrajectoryMetrics::evaluate(groundTruth, traj);
        fig.ate = AteFigures{ev.ate.stats.rmse, ev.ate.stats.mean, ev.ate.stats.median,
                             ev.ate.stats.max,  ev.pairs,          ev.unmatchedEstimatePoses};
      }
    }
    if (frameLog.is_open()) {
      frameLog.close();  // the last buffered lines may fail too
      if (!frameLog)
        throw std::runtime_error(
            writeErrorMessage(argFrameLog.getValue(), "write error", frameLogStaged));
    }
    writeMapOutputs(outputs, slam, traj, argSaveMap.getValue(), argDense.getValue(),
                    argRender.getValue(), argSimpleMap.getValue(), quiet);
    outputs.commit();
    if (!quiet && argSaveMap.isSet())
      std::fprintf(stderr, "[slamdunk-rawlog] map written to %s\n", argSaveMap.getValue().c_str());
    if (!quiet && argRender.isSet())
      std::fprintf(stderr, "[slamdunk-rawlog] picture written to %s (and its .3Dscene)\n",
                   argRender.getValue().c_str());
    printRunSummary(fig, argJson.getValue());
    // Out now: stdout may be a pipe (fully buffered), and the summary must not depend on how
    // the viewer's window and the process end.
    std::fflush(stdout);
#ifdef SLAMDUNK_WITH_VIEWER
    if (gui && argGuiWait.getValue() && gui->isOpen()) {
      std::fprintf(stderr,
                   "[slamdunk-rawlog] close the viewer window (or press q in it) to exit\n");
      gui->waitUntilClosed();
    }
#endif
    if (!readError.empty()) {
      std::cerr << "slamdunk-rawlog: error: " << readError << "; the outputs cover the "
                << fig.decodeMs.size() << " frames before it\n";
      return 2;
    }
    return 0;
  } catch (const TCLAP::ArgException& e) {
    std::cerr << "slamdunk-rawlog: " << e.error() << " (" << e.argId() << "); see --help\n";
  } catch (const std::exception& e) {
    std::cerr << "slamdunk-rawlog: error: " << e.what() << "\n";
  }
  return 1;
}
