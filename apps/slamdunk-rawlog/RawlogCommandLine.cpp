#include "RawlogCommandLine.h"

#include <slamdunk/core/CommandLine.h>

#include <cstdio>
#include <list>

namespace slamdunk {

namespace {

using Run = apps::RawlogRunOptions;

/// The options naming a file, each read into its field of the run's options.
struct FileOption {
  const char *flag, *name, *help, *type;
  std::string Run::*field;
  bool required = false;
};

const FileOption kFiles[] = {
    {"c", "config",
     "pipeline INI (sections [features] [local_map] [tracker] [optimizer] [loop_closing] "
     "[grid_map] [slam]); default: "
     "built-in values, the same as config-ini/slamdunk-default.ini",
     "PIPELINE.ini", &Run::configFile},
    {"t", "trajectory", "output TUM trajectory of all frames", "OUT.txt", &Run::trajectory, true},
    {"k", "keyframes", "output TUM trajectory of the keyframes (default: OUT_keyframes.txt)",
     "KF.txt", &Run::keyframes},
    {"g", "gt", "ground truth (TUM file): print ATE at the end", "GT.txt", &Run::groundTruth},
    {"", "load-map",
     "start from a saved map: the camera relocalizes in it, then mapping continues (trajectory "
     "in the saved map's frame)",
     "IN.map", &Run::startMap},
    {"", "save-map",
     "write the keyframe-graph map (slamdunk::CKeyframeGraphMap, readable by slamdunk-render and "
     "by MRPT tools that load libslamdunk_mrpt_map.so)",
     "OUT.map", &Run::map},
    {"", "simplemap", "export keyframe poses + observations as an MRPT .simplemap", "OUT.simplemap",
     &Run::simpleMap},
    {"", "dense",
     "write the dense reconstruction: PREFIX.ply and PREFIX.pcd (voxel-filtered coloured cloud) "
     "and PREFIX.ot / PREFIX.bt (OctoMap)",
     "PREFIX", &Run::dense},
    {"", "gridmap",
     "write the 2D occupancy grid a robot navigates on: PREFIX.gridmap (MRPT's "
     "COccupancyGridMap2D), PREFIX.png and PREFIX.yaml (ROS map_server); floor, obstacle heights "
     "and resolution in the INI's [grid_map]",
     "PREFIX", &Run::gridMap},
    {"", "render", "render the map offscreen to a PNG (and a .3Dscene for SceneViewer3D)",
     "OUT.png", &Run::render},
    {"", "frame-log",
     "write one CSV line per frame (status, features, matches, inliers, overlap, keyframe, loop "
     "closure, ms per stage; the columns of slamdunk-live's frame log)",
     "FRAMES.csv", &Run::frameLog},
};

/// The switches, each setting a flag of the command line.
struct Switch {
  const char *flag, *name, *help;
  bool RawlogCommandLine::*field;
};

const Switch kSwitches[] = {
    {"", "map-images",
     "keep keyframe colour+depth in the map (needed later for dense outputs from a saved map; "
     "about 0.6 MB per keyframe in the file)",
     &RawlogCommandLine::mapImages},
    {"", "localize",
     "with --load-map: localization only, the map is not changed (no keyframe is added); frames "
     "whose view the map covers too little are counted as outside the map (same as [tracker] "
     "localization_only=true)",
     &RawlogCommandLine::localize},
    {"", "extend-map",
     "with --localize: where the map covers too little of the view, add keyframes as mapping "
     "does (the loaded keyframes stay as they are; same as [tracker] extend_map=true)",
     &RawlogCommandLine::extendMap},
    {"", "json", "print the summary as JSON", &RawlogCommandLine::json},
    {"", "no-optimization",
     "disable the local optimization (same as [slam] local_optimization=false)",
     &RawlogCommandLine::noOptimization},
    {"q", "quiet", "no progress output", &RawlogCommandLine::quiet},
    {"", "gui",
     "show the run in a 3D window (map, trajectory, camera, image with its features, status); "
     "keys in the window: space pauses and resumes, s or the right arrow processes one frame, q "
     "closes the window (the run goes on). Results are the same with and without it",
     &RawlogCommandLine::gui},
    {"", "gui-wait",
     "with --gui: keep the window open after the run, until it is closed (or q is pressed in it)",
     &RawlogCommandLine::guiWait},
    {"", "gui-paused",
     "with --gui: start paused (space runs, s or the right arrow processes one frame)",
     &RawlogCommandLine::guiPaused},
};

}  // namespace

std::optional<int> parseRawlogCommandLine(int argc, char** argv, RawlogCommandLine& out) {
  TCLAP::CmdLine cmd(
      "SlamDunk RGB-D SLAM over a rawlog of CObservation3DRangeScan (camera calibration taken "
      "from the observations). Writes the trajectory of every tracked frame in TUM format "
      "(optical frame, world = first camera), the keyframe trajectory beside it, and prints a "
      "run summary. Lost frames are reported and left out of the trajectory.",
      ' ', "1.0");
  TCLAP::UnlabeledValueArg<std::string> in("IN", "input rawlog", true, "", "IN.rawlog", cmd);
  std::list<TCLAP::ValueArg<std::string>> files;
  for (const FileOption& f : kFiles)
    files.emplace_back(f.flag, f.name, f.help, f.required, "", f.type, cmd);
  TCLAP::ValueArg<size_t> maxFrames("", "max-frames", "process at most N frames (0 = all)", false,
                                    0, "N", cmd);
  TCLAP::ValueArg<size_t> firstFrame("", "first-frame", "skip the frames before this index", false,
                                     0, "I", cmd);
  std::list<TCLAP::SwitchArg> switches;
  for (const Switch& s : kSwitches) switches.emplace_back(s.flag, s.name, s.help, cmd);
  if (const auto exitCode = parseCommandLine(cmd, argc, argv, "slamdunk-rawlog")) return exitCode;

  auto file = files.begin();
  for (const FileOption& f : kFiles) out.run.*f.field = (file++)->getValue();
  auto flag = switches.begin();
  for (const Switch& s : kSwitches) out.*s.field = (flag++)->getValue();
  if ((out.guiWait || out.guiPaused) && !out.gui)
    throw std::runtime_error("--gui-wait and --gui-paused go with --gui");
  apps::RawlogRunOptions& o = out.run;
  o.rawlog = in.getValue();
  o.firstFrame = firstFrame.getValue();
  o.maxFrames = maxFrames.getValue();
  if (!o.configFile.empty()) o.slam = SlamOptions::fromFile(o.configFile);
  if (out.noOptimization) o.slam.localOptimization = false;
  if (out.mapImages) o.slam.tracker.keepKeyframeImages = true;
  if (out.extendMap && !out.localize) throw std::runtime_error("--extend-map goes with --localize");
  if (out.localize) o.slam.tracker.localizationOnly = true;
  if (out.extendMap) o.slam.tracker.extendMap = true;
  if (o.slam.tracker.localizationOnly && o.startMap.empty())
    throw std::runtime_error(
        "localization only (--localize) needs the map to localize in: "
        "--load-map IN.map");
  if (!out.quiet)
    o.log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  return std::nullopt;
}

}  // namespace slamdunk
