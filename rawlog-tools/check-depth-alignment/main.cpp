// check-depth-alignment: does a trajectory agree with the depth images of its rawlog? Frame
// pairs some way apart are aligned by their depth alone, point-to-plane, starting from the
// trajectory's relative pose, and the tool reports how far the alignment moved them.

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/Statistics.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/RotationScale.h>
#include <slamdunk/eval/TrajectoryAssociation.h>
#include <slamdunk/tracking/DepthPairCheck.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

using namespace slamdunk;

namespace {

const char* kDescription =
    "Checks a camera trajectory (TUM format, the colour camera's optical frame, e.g. a ground "
    "truth or slamdunk-rawlog's -t output) against the depth images of the rawlog it belongs "
    "to. Frames --step apart (every --every frames) are aligned by their depth alone "
    "(point-to-plane, fitted normals), starting from the trajectory's relative pose between "
    "them; pairs whose alignment is not accepted (too little overlap, a large residual, a "
    "geometry that does not hold all six degrees of freedom) are counted and left out. Prints:\n"
    "  the rotation scale per camera axis (x right, y down, z forward): how much the depth "
    "alignment turns for each turn of the trajectory (least squares; 1 = the depth agrees; "
    "turns about x and y, tilt and pan, are held mostly by the surfaces' normals, which a "
    "focal length error hardly changes); n/a for an axis the trajectory hardly turns about;\n"
    "  the median point-to-plane residual (mm) at the trajectory's poses and after alignment;\n"
    "  the rms rotation (deg) and translation (mm) the alignment moved the pairs by.\n"
    "A frame's pose is the trajectory interpolated at its stamp (poses at most --max-gap "
    "apart). Exit status 0 on success, 1 on any error (unreadable input, no pair aligned).";

struct TrackedFrame {
  size_t index = 0;
  Pose pose;
  RgbdFrame frame;
};

struct Summary {
  size_t frames = 0, framesWithPose = 0, pairs = 0, aligned = 0;
  std::map<std::string, size_t> failures;
  eval::RotationScale rotationScale;
  std::vector<double> residualGiven, residualAligned, rotationMoved, translationMoved;
};

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? std::nan("") : std::sqrt(s / static_cast<double>(v.size()));
}

std::string number(double v, const char* fmt = "%.4f") {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

void addPair(const TrackedFrame& source, const TrackedFrame& target,
             const DepthPairCheckOptions& options, Summary& s) {
  ++s.pairs;
  const Pose given = target.pose.inverse() * source.pose;
  const DepthPairCheck c = checkDepthPair(source.frame, target.frame, given, options);
  if (!c.aligned) {
    // The reason without its figures, so that failures of one kind count together.
    ++s.failures[c.failure.substr(0, c.failure.find_first_of("0123456789"))];
    return;
  }
  ++s.aligned;
  s.rotationScale.add(given.linear(), c.alignedPose.linear());
  s.residualGiven.push_back(c.medianResidualGiven);
  s.residualAligned.push_back(c.medianResidualAligned);
  const Pose moved = c.alignedPose * given.inverse();
  s.rotationMoved.push_back(Eigen::AngleAxisd(moved.linear()).angle() * 180.0 / M_PI);
  s.translationMoved.push_back(moved.translation().norm());
}

Trajectory loadTrajectory(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("trajectory file '" + path + "' does not exist or is not a file");
  Trajectory t = eval::sortedUniqueByStamp(readTumTrajectory(path));
  if (t.size() < 2)
    throw std::runtime_error("trajectory file '" + path + "' has fewer than 2 poses");
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  return slamdunk::runTool("check-depth-alignment", [&] {
    TCLAP::CmdLine cmd(kDescription, ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> rawlogArg("RAWLOG", "Rawlog of RGB-D observations.", true,
                                                    "", "RAWLOG", cmd);
    TCLAP::UnlabeledValueArg<std::string> trajArg("TRAJECTORY", "Trajectory (TUM format).", true,
                                                  "", "TRAJECTORY.txt", cmd);
    TCLAP::ValueArg<int> stepArg("", "step", "Frames between the two of a pair. Default 20.", false,
                                 20, "frames", cmd);
    TCLAP::ValueArg<int> everyArg("", "every", "Frames between pairs' first frames. Default 10.",
                                  false, 10, "frames", cmd);
    TCLAP::ValueArg<double> maxGapArg(
        "", "max-gap",
        "Largest gap (s) between the two trajectory poses a frame's pose is interpolated "
        "between. Default 0.04.",
        false, 0.04, "seconds", cmd);
    TCLAP::SwitchArg jsonArg("", "json", "Print one JSON object on stdout instead of text.", cmd);
    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "check-depth-alignment"))
      return *exitCode;
    const int step = stepArg.getValue(), every = everyArg.getValue();
    if (step < 1 || every < 1) throw std::runtime_error("--step and --every must be at least 1");
    const double maxGap = maxGapArg.getValue();
    if (!(maxGap > 0) || !std::isfinite(maxGap))
      throw std::runtime_error("--max-gap must be a positive number of seconds");

    const Trajectory trajectory = loadTrajectory(trajArg.getValue());
    RawlogReader reader(rawlogArg.getValue());
    const DepthPairCheckOptions options;
    Summary s;
    std::deque<TrackedFrame> recent;  // the last `step` frames, for the pairs' first frames
    for (size_t index = 0;; ++index) {
      const auto obs = reader.next();
      if (!obs) break;
      ++s.frames;
      RgbdFrame frame = RgbdFrame::fromObservation(*obs);
      obs->unload();
      const Trajectory at = eval::interpolatedAt(trajectory, {frame.timestamp()}, maxGap);
      while (!recent.empty() && recent.front().index + step < index) recent.pop_front();
      if (at.empty()) continue;
      ++s.framesWithPose;
      if (!recent.empty() && recent.front().index + step == index &&
          recent.front().index % every == 0)
        addPair(recent.front(), {index, at.front().pose, frame}, options, s);
      recent.push_back({index, at.front().pose, std::move(frame)});
    }
    if (s.aligned == 0) {
      std::string why;
      for (const auto& [reason, count] : s.failures)
        why += "; " + std::to_string(count) + " x " + reason;
      throw std::runtime_error("no frame pair was aligned (" + std::to_string(s.pairs) +
                               " pairs with poses among " + std::to_string(s.frames) + " frames" +
                               why + ")");
    }

    const Eigen::Vector3d scale = s.rotationScale.scale();
    const Eigen::Vector3d scaleError = s.rotationScale.standardError();
    const Eigen::Vector3d turn = s.rotationScale.referenceRmsDegrees();
    if (jsonArg.getValue()) {
      std::printf(
          "{\n  \"frames\": %zu, \"frames_with_pose\": %zu, \"pairs\": %zu, \"aligned\": %zu,\n"
          "  \"rotation_scale_xyz\": [%s, %s, %s],\n"
          "  \"rotation_scale_standard_error_xyz\": [%s, %s, %s],\n"
          "  \"trajectory_rms_turn_deg_xyz\": [%s, %s, %s],\n"
          "  \"median_residual_given_mm\": %s, \"median_residual_aligned_mm\": %s,\n"
          "  \"rms_rotation_moved_deg\": %s, \"rms_translation_moved_mm\": %s\n}\n",
          s.frames, s.framesWithPose, s.pairs, s.aligned, number(scale.x()).c_str(),
          number(scale.y()).c_str(), number(scale.z()).c_str(), number(scaleError.x()).c_str(),
          number(scaleError.y()).c_str(), number(scaleError.z()).c_str(),
          number(turn.x(), "%.3f").c_str(), number(turn.y(), "%.3f").c_str(),
          number(turn.z(), "%.3f").c_str(), number(1000 * median(s.residualGiven), "%.3f").c_str(),
          number(1000 * median(s.residualAligned), "%.3f").c_str(),
          number(rms(s.rotationMoved), "%.3f").c_str(),
          number(1000 * rms(s.translationMoved), "%.2f").c_str());
    } else {
      auto text = [](double v) { return std::isfinite(v) ? number(v) : std::string("n/a"); };
      std::printf("frames %zu, with a pose %zu; pairs %d frames apart: %zu, aligned %zu\n",
                  s.frames, s.framesWithPose, step, s.pairs, s.aligned);
      for (const auto& [reason, count] : s.failures)
        std::printf("  not aligned: %zu x %s\n", count, reason.c_str());
      std::printf("rotation scale (depth alignment / trajectory), standard error in brackets:\n");
      const char* axes[] = {"x (tilt)", "y (pan) ", "z (roll)"};
      for (int a = 0; a < 3; ++a)
        std::printf("  about %s %s (%s), the trajectory turning %.2f deg rms per pair\n", axes[a],
                    text(scale[a]).c_str(), text(scaleError[a]).c_str(), turn[a]);
      std::printf("median point-to-plane residual: %.3f mm at the trajectory, %.3f mm aligned\n",
                  1000 * median(s.residualGiven), 1000 * median(s.residualAligned));
      std::printf("the alignment moved the pairs by %.3f deg and %.2f mm (rms)\n",
                  rms(s.rotationMoved), 1000 * rms(s.translationMoved));
    }
    return 0;
  });
}
