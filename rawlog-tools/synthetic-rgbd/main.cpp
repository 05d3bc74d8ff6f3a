// synthetic-rgbd: renders a synthetic RGB-D sequence of a textured indoor scene (one room, or an
// office of four rooms and corridors) with exact ground truth into an MRPT rawlog
// (CObservation3DRangeScan) and a TUM ground-truth file.

#include <slamdunk/synthetic/SyntheticSequence.h>

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/MemoryReuse.h>
#include <slamdunk/core/Stopwatch.h>

#include <cstdio>
#include <stdexcept>
#include <string>

int main(int argc, char** argv) {
  slamdunk::keepFreedMemoryForReuse();  // frames one after the other: their pages stay mapped
  return slamdunk::runTool("synthetic-rgbd", [&] {
    TCLAP::CmdLine cmd(
        "Renders a synthetic RGB-D sequence (a textured indoor scene, software OpenGL through EGL, "
        "no display needed) into an MRPT rawlog of CObservation3DRangeScan observations "
        "(observation-only format, the layout tum2rawlog produces: 640x480, fx=fy=525, "
        "depth as raw 16-bit units of 0.2 mm, z-depth, exact) and writes the exact camera "
        "trajectory as a TUM ground-truth file (optical frame, same timestamps, 30 Hz). The world "
        "frame has y pointing down (gravity) and the floor 1.3 m below the origin. The trajectory "
        "chooses the scene: 'sweep' and 'loop' film a single 7 x 6 m room, 'tour' walks through "
        "the 'office', four such rooms at the corners of a 16 x 13 m rectangle joined by 2.4 m "
        "wide corridors into a ring "
        "(boxes along the walls; every surface has its own, never repeated, texture). Same "
        "options and seed give the same sequence.",
        ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argOut("OUT", "output rawlog file", true, "",
                                                 "OUT.rawlog", cmd);
    TCLAP::ValueArg<std::string> argTrajectory(
        "t", "trajectory",
        "camera path: 'sweep' (hand-held sweep in the room, 150 frames, ~45 cm, 30 deg pan), "
        "'loop' (1 m circle in the room looking outward at the walls, 400 frames, ends where it "
        "started) or 'tour' (once round the office: 55 m at a walking pace of ~0.5 m/s, "
        "3300 frames = 110 s, looking partly at the walls, ends where it started; a scale "
        "benchmark); hand-held, in the room: 'rotations' (quick sweeps about each axis up to "
        "~90 deg/s, 330 frames), 'shake' (a slow sweep under a shaking hand, 300 frames), "
        "'scan' (a 2.5-minute room scan, two laps looking outward, 4500 frames), 'dwell' (a "
        "minute in one spot, turning about all axes up to ~90 deg/s, 1800 frames)",
        false, "loop", "sweep|loop|tour|rotations|shake|scan|dwell", cmd);
    TCLAP::ValueArg<int> argFrames(
        "n", "frames",
        "number of frames spread over the whole path (0 = the trajectory's default; fewer frames "
        "= a faster camera)",
        false, 0, "N", cmd);
    TCLAP::ValueArg<int> argFirstFrames(
        "", "first-frames",
        "keep only the first N frames of the path, at its own speed (0 = all; e.g. 600 = the "
        "first 20 s of 'scan')",
        false, 0, "N", cmd);
    TCLAP::ValueArg<int> argSkipFrames(
        "", "skip-frames",
        "leave out the path's first N frames (before --first-frames counts): a second session "
        "of the same walk, its frames and stamps as in the whole path",
        false, 0, "N", cmd);
    TCLAP::SwitchArg argTwinRooms(
        "", "twin-rooms",
        "tour: the office's room C built as a copy of room A (its walls and boxes, turned half a "
        "turn): the same views in two rooms 20 m apart",
        cmd);
    TCLAP::SwitchArg argBareCorridor(
        "", "bare-corridor",
        "tour: the corridor from room B to room C painted almost plain (2 % of the usual "
        "texture's shapes on its walls, floor and ceiling; its two cabinets keep theirs): 7 m "
        "with few features",
        cmd);
    TCLAP::ValueArg<unsigned> argSeed("s", "seed", "texture (and depth noise) seed", false, 1, "S",
                                      cmd);
    TCLAP::ValueArg<std::string> argGt(
        "g", "gt",
        "where to write the ground truth (default: OUT without .rawlog + _groundtruth.txt)", false,
        "", "GT.txt", cmd);
    TCLAP::SwitchArg argExternal(
        "e", "external-images",
        "store images in <OUT name>_Images/ beside the rawlog (colour PNG, depth as MRPT "
        "external matrices) instead of inside it",
        cmd);
    TCLAP::ValueArg<int> argJpeg(
        "", "jpeg-quality",
        "with --external-images: colour as JPEG of quality Q (1-100) instead of lossless PNG "
        "(a quarter of the disk and faster to read; the depth stays exact)",
        false, 0, "Q", cmd);
    TCLAP::ValueArg<double> argNoise(
        "", "depth-noise",
        "standard deviation (metres) of Gaussian noise added to every valid depth (default 0 = "
        "exact depth)",
        false, 0.0, "SIGMA", cmd);
    TCLAP::SwitchArg argKinect(
        "", "kinect-depth",
        "simulate a Kinect v1's depth (disparity noise growing with z^2, 1/8-pixel disparity "
        "steps, 0.5 px lateral jitter) instead of exact depth",
        cmd);
    TCLAP::ValueArg<std::string> argKinectTwin(
        "", "kinect-twin",
        "also write the sequence --kinect-depth would give (the same colour images, Kinect-like "
        "depth; its ground truth and images beside it) to this rawlog: each frame is rendered "
        "once for both, the pair takes about half the time of two runs",
        false, "", "TWIN.rawlog", cmd);
    TCLAP::ValueArg<int> argSupersampling(
        "", "supersampling",
        "colour anti-aliasing: render K x K samples per pixel and average them (odd K: 1 = off, "
        "3 = default); depth is always the exact z at the pixel centre",
        false, 3, "K", cmd);
    TCLAP::ValueArg<double> argExposure(
        "", "exposure-ms", "motion blur: colour integrated over this exposure time (default 0)",
        false, 0.0, "MS", cmd);
    TCLAP::ValueArg<double> argRollingShutter(
        "", "rolling-shutter-ms",
        "rolling shutter: the bottom row is exposed this long after the top row (default 0)", false,
        0.0, "MS", cmd);
    TCLAP::SwitchArg argAutoExposure(
        "", "auto-exposure", "a slowly changing colour gain (0.6-1.5), saturating at white", cmd);
    TCLAP::ValueArg<double> argDepthOffset(
        "", "depth-offset-ms", "depth captured this long after colour (negative: before)", false,
        0.0, "MS", cmd);
    TCLAP::ValueArg<double> argFocalError(
        "", "stated-focal-error",
        "the rawlog states focal lengths this many percent larger than the rendering's: a "
        "camera known by its nominal intrinsics, not calibrated (default 0)",
        false, 0.0, "PERCENT", cmd);
    TCLAP::SwitchArg argHandHeld(
        "", "hand-held",
        "the hand-held camera preset: --exposure-ms 10 --rolling-shutter-ms 20 --auto-exposure "
        "--depth-offset-ms 5 (options given explicitly win)",
        cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "no progress output", cmd);
    if (const auto exitCode = slamdunk::parseCommandLine(cmd, argc, argv, "synthetic-rgbd"))
      return *exitCode;

    slamdunk::SyntheticOptions opts;
    opts.trajectory = argTrajectory.getValue();
    opts.frames = argFrames.getValue();
    opts.firstFrames = argFirstFrames.getValue();
    opts.skipFrames = argSkipFrames.getValue();
    opts.twinRooms = argTwinRooms.getValue();
    opts.bareCorridor = argBareCorridor.getValue();
    opts.seed = argSeed.getValue();
    opts.depthNoiseSigma = argNoise.getValue();
    opts.kinectDepth = argKinect.getValue();
    opts.externalImages = argExternal.getValue();
    opts.jpegQuality = argJpeg.getValue();
    opts.supersampling = argSupersampling.getValue();
    if (argHandHeld.getValue()) opts.enableHandHeldEffects();
    if (argExposure.isSet()) opts.exposureMs = argExposure.getValue();
    if (argRollingShutter.isSet()) opts.rollingShutterMs = argRollingShutter.getValue();
    if (argAutoExposure.isSet()) opts.autoExposure = true;
    if (argDepthOffset.isSet()) opts.depthTimeOffsetMs = argDepthOffset.getValue();
    opts.statedFocalErrorPercent = argFocalError.getValue();
    opts.validate();  // a clear error before any rendering or file output
    if (argKinectTwin.isSet() && opts.kinectDepth)
      throw std::invalid_argument(
          "--kinect-twin and --kinect-depth exclude each other (the twin "
          "is the Kinect-depth copy of an exact-depth sequence)");

    const auto start = slamdunk::SteadyClock::now();
    const auto sum = slamdunk::writeSyntheticSequence(
        opts, argOut.getValue(), argGt.getValue(),
        slamdunk::frameProgress("synthetic-rgbd: rendered", argQuiet.getValue()),
        argKinectTwin.getValue());
    const double secs = slamdunk::msSince(start) / 1000.0;

    const auto& st = sum.stats;
    std::printf("synthetic-rgbd summary\n");
    std::printf("  trajectory:       %s, seed %u\n", opts.trajectory.c_str(), opts.seed);
    std::printf("  scene:            %s\n", sum.scene.c_str());
    std::printf("  frames:           %zu (%.2f s at 30 Hz)\n", sum.frames, st.duration);
    std::printf("  path length:      %.3f m, total rotation %.1f deg\n", st.pathLength,
                st.totalRotationDeg);
    std::printf("  max speed:        %.2f m/s, %.1f deg/s\n", st.maxSpeed, st.maxAngularSpeedDeg);
    if (st.maxSpeed > 0.6 || st.maxAngularSpeedDeg > 100)
      std::printf("  note:             faster than a hand-held camera (use more --frames)\n");
    if (opts.motionEffects() || opts.autoExposure || opts.depthTimeOffsetMs != 0)
      std::printf(
          "  camera effects:   exposure %.1f ms, rolling shutter %.1f ms, auto exposure "
          "%s, depth %+.1f ms after colour\n",
          opts.exposureMs, opts.rollingShutterMs, opts.autoExposure ? "on" : "off",
          opts.depthTimeOffsetMs);
    if (opts.statedFocalErrorPercent != 0)
      std::printf("  stated focal:     %.2f px (rendered with %.2f px)\n",
                  opts.statedIntrinsics().fx, opts.fx);
    if (opts.depthNoiseSigma > 0)
      std::printf("  depth noise:      sigma %.4f m\n", opts.depthNoiseSigma);
    std::printf("  rawlog:           %s\n", sum.rawlogPath.c_str());
    if (!sum.imagesFolder.empty())
      std::printf("  images folder:    %s\n", sum.imagesFolder.c_str());
    std::printf("  ground truth:     %s\n", sum.groundTruthPath.c_str());
    if (!sum.kinectTwinRawlogPath.empty())
      std::printf("  Kinect twin:      %s (ground truth %s)\n", sum.kinectTwinRawlogPath.c_str(),
                  sum.kinectTwinGroundTruthPath.c_str());
    std::printf("  time:             %.2f s (%.1f ms/frame rendering)\n", secs,
                sum.frames ? 1000.0 * sum.renderSeconds / sum.frames : 0.0);
    return 0;
  });
}
