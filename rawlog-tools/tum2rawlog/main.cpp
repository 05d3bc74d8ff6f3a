// tum2rawlog: TUM RGB-D folder -> MRPT rawlog of CObservation3DRangeScan (+ TUM ground truth).

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/MemoryReuse.h>
#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/core/TumToRawlog.h>

#include <cstdio>
#include <iostream>

int main(int argc, char** argv) {
  slamdunk::keepFreedMemoryForReuse();  // images one after the other: their pages stay mapped
  return slamdunk::runTool("tum2rawlog", [&] {
    TCLAP::CmdLine cmd(
        "Converts a TUM RGB-D benchmark folder (rgb.txt, depth.txt, optional groundtruth.txt) "
        "into an MRPT rawlog of CObservation3DRangeScan observations (observation-only format). "
        "Colour and depth are associated the TUM way (nearest stamps, |dt| < max-dt, one-to-one); "
        "depth is copied as raw 16-bit values with rangeUnits = 1/depth_factor. Ground truth, if "
        "present, is written beside the rawlog as a TUM trajectory file.",
        ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argSeq("SEQ_DIR", "TUM-layout input folder", true, "",
                                                 "SEQ_DIR", cmd);
    TCLAP::UnlabeledValueArg<std::string> argOut("OUT", "output rawlog file", true, "",
                                                 "OUT.rawlog", cmd);
    TCLAP::ValueArg<std::string> argCamera(
        "c", "camera",
        "camera calibration INI ([CAMERA] resolution, fx, fy, cx, cy, dist, depth_factor); see "
        "config-ini/cameras/. Default: generic Kinect/Xtion (fx=fy=525, cx=319.5, cy=239.5, "
        "factor 5000)",
        false, "", "CAMERA.ini", cmd);
    TCLAP::ValueArg<std::string> argGt(
        "g", "gt",
        "where to write the ground truth (default: OUT without .rawlog + "
        "_groundtruth.txt)",
        false, "", "GT.txt", cmd);
    TCLAP::SwitchArg argExternal(
        "e", "external-images",
        "store images in <OUT name>_Images/ beside the rawlog instead of inside it (colour files "
        "copied unchanged, depth as MRPT external matrices)",
        cmd);
    TCLAP::SwitchArg argGtObs(
        "", "gt-observations",
        "also write a CObservationRobotPose 'GROUND_TRUTH' (sensor frame) after each frame that "
        "has a ground-truth pose within max-dt",
        cmd);
    TCLAP::ValueArg<double> argMaxDt("", "max-dt",
                                     "maximum colour/depth stamp difference in seconds (0.02)",
                                     false, 0.02, "SECONDS", cmd);
    TCLAP::ValueArg<size_t> argMaxFrames("", "max-frames", "convert at most N frames (0 = all)",
                                         false, 0, "N", cmd);
    TCLAP::ValueArg<size_t> argStride(
        "", "stride",
        "keep every N-th frame (1 = all): the same motion at 1/N the frame rate, N times the "
        "motion between frames, as a faster hand would give",
        false, 1, "N", cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "no progress output", cmd);
    if (const auto exitCode = slamdunk::parseCommandLine(cmd, argc, argv, "tum2rawlog"))
      return *exitCode;

    slamdunk::TumToRawlogOptions opts;
    opts.sequenceFolder = argSeq.getValue();
    opts.rawlogPath = argOut.getValue();
    opts.groundTruthPath = argGt.getValue();
    opts.externalImages = argExternal.getValue();
    opts.groundTruthObservations = argGtObs.getValue();
    opts.maxDifference = argMaxDt.getValue();
    opts.maxFrames = argMaxFrames.getValue();
    opts.stride = argStride.getValue();
    if (opts.stride < 1) throw std::invalid_argument("--stride must be at least 1");
    if (!(opts.maxDifference > 0)) throw std::invalid_argument("--max-dt must be positive");
    if (argCamera.isSet()) {
      opts.calibration = slamdunk::RgbdCameraCalibration::loadFromIni(argCamera.getValue());
    } else {
      std::cerr << "tum2rawlog: no --camera given, using the generic Kinect/Xtion calibration\n";
    }

    const auto start = slamdunk::SteadyClock::now();
    const auto sum = slamdunk::convertTumToRawlog(
        opts, slamdunk::frameProgress("tum2rawlog:", argQuiet.getValue()));
    const double secs = slamdunk::msSince(start) / 1000.0;

    std::printf("tum2rawlog summary\n");
    std::printf("  input:            %s\n", opts.sequenceFolder.c_str());
    std::printf("  rawlog:           %s\n", opts.rawlogPath.c_str());
    if (!sum.imagesFolder.empty())
      std::printf("  images folder:    %s\n", sum.imagesFolder.c_str());
    std::printf("  frames:           %zu\n", sum.frames);
    std::printf("  pairs dropped:    %zu colour and %zu depth images without a partner\n",
                sum.rgbUnpaired, sum.depthUnpaired);
    std::printf("  time span:        %.6f .. %.6f (%.3f s)\n", sum.firstStamp, sum.lastStamp,
                sum.lastStamp - sum.firstStamp);
    if (!sum.groundTruthPath.empty())
      std::printf("  ground truth:     %zu poses -> %s\n", sum.groundTruthPoses,
                  sum.groundTruthPath.c_str());
    else
      std::printf("  ground truth:     none (no groundtruth.txt)\n");
    if (opts.groundTruthObservations)
      std::printf("  gt observations:  %zu\n", sum.groundTruthObservations);
    std::printf("  conversion time:  %.2f s\n", secs);
    return 0;
  });
}
