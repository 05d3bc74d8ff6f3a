// evaluate-trajectory: ATE and RPE of an estimated TUM trajectory against ground truth, with the
// semantics of the TUM RGB-D benchmark scripts (associate.py, evaluate_ate.py, evaluate_rpe.py).

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/TrajectoryMetrics.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>

using namespace slamdunk;
using namespace slamdunk::eval;

namespace {

const char* kDescription =
    "Compares an estimated camera trajectory with ground truth, both in the TUM RGB-D format "
    "('timestamp tx ty tz qx qy qz qw' per line, '#' comments), and prints:\n"
    "  ATE: absolute trajectory error. Poses are paired by timestamp as associate.py does "
    "(|dt| < --max-dt, one-to-one, smallest differences first); the estimated positions are "
    "rigidly aligned onto the ground-truth positions (rotation + translation, no scale); then "
    "rmse/mean/median/std/min/max of the remaining position errors, in metres.\n"
    "  RPE: relative pose error as evaluate_rpe.py --fixed_delta --delta_unit s computes it, over "
    "all pose pairs --rpe-delta seconds apart: translational error (m) and rotational error (deg) "
    "of the relative motion over that interval -- m/s and deg/s for the default 1 s. With it, "
    "the rotation scale per camera axis (x right, y down, z forward) over the same pairs: how "
    "much the estimate turns for each turn of the ground truth (least squares; turns about x and "
    "y, tilt and pan, are read through the focal length, turns about z, roll, are not); null for "
    "an axis the ground truth hardly turns about.\n"
    "Also reported: how many pairs associated and how many estimated poses have no ground-truth "
    "partner. With --json a single JSON object goes to stdout instead. Exit status 0 on success, 1 "
    "on any error (unreadable or malformed file, no associated pairs, fewer than 3 pairs).";

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

void printJson(const std::string& gtPath, const std::string& estPath, const EvaluationOptions& opt,
               const TrajectoryEvaluation& ev) {
  const ErrorStatistics& a = ev.ate.stats;
  const RpeResult& r = ev.rpe;
  // RPE numbers are null when RPE could not be computed (rpe_error says why).
  auto rpe = [&](double v) { return r.valid ? jsonNumber(v) : std::string("null"); };
  std::cout << "{\n"
            << "  \"groundtruth_file\": " << jsonString(gtPath) << ",\n"
            << "  \"estimate_file\": " << jsonString(estPath) << ",\n"
            << "  \"max_dt_s\": " << jsonNumber(opt.maxDifference) << ",\n"
            << "  \"interpolated_groundtruth\": " << (opt.interpolate ? "true" : "false") << ",\n"
            << "  \"groundtruth_poses\": " << ev.groundTruthPoses << ",\n"
            << "  \"estimate_poses\": " << ev.estimatePoses << ",\n"
            << "  \"pairs\": " << ev.pairs << ",\n"
            << "  \"unmatched_estimate_poses\": " << ev.unmatchedEstimatePoses << ",\n"
            << "  \"duplicate_stamps_dropped\": " << ev.duplicateStampsDropped << ",\n"
            << "  \"ate_rmse_m\": " << jsonNumber(a.rmse) << ",\n"
            << "  \"ate_mean_m\": " << jsonNumber(a.mean) << ",\n"
            << "  \"ate_median_m\": " << jsonNumber(a.median) << ",\n"
            << "  \"ate_std_m\": " << jsonNumber(a.std) << ",\n"
            << "  \"ate_min_m\": " << jsonNumber(a.min) << ",\n"
            << "  \"ate_max_m\": " << jsonNumber(a.max) << ",\n"
            << "  \"rpe_delta_s\": " << jsonNumber(r.delta) << ",\n"
            << "  \"rpe_pairs\": " << r.pairs << ",\n"
            << "  \"rpe_trans_rmse_m_per_s\": " << rpe(r.translation.rmse) << ",\n"
            << "  \"rpe_trans_mean_m_per_s\": " << rpe(r.translation.mean) << ",\n"
            << "  \"rpe_trans_median_m_per_s\": " << rpe(r.translation.median) << ",\n"
            << "  \"rpe_trans_max_m_per_s\": " << rpe(r.translation.max) << ",\n"
            << "  \"rpe_rot_rmse_deg_per_s\": " << rpe(r.rotationDegrees.rmse) << ",\n"
            << "  \"rpe_rot_mean_deg_per_s\": " << rpe(r.rotationDegrees.mean) << ",\n"
            << "  \"rpe_rot_median_deg_per_s\": " << rpe(r.rotationDegrees.median) << ",\n"
            << "  \"rpe_rot_max_deg_per_s\": " << rpe(r.rotationDegrees.max) << ",\n"
            << "  \"rotation_scale_xyz\": [" << rpe(r.rotationScale.x()) << ", "
            << rpe(r.rotationScale.y()) << ", " << rpe(r.rotationScale.z()) << "],\n"
            << "  \"rpe_error\": " << (r.valid ? std::string("null") : jsonString(r.reason))
            << "\n}\n";
}

void printHuman(const std::string& gtPath, const std::string& estPath, const EvaluationOptions& opt,
                const TrajectoryEvaluation& ev) {
  const ErrorStatistics& a = ev.ate.stats;
  const RpeResult& r = ev.rpe;
  std::printf("ground truth: %s (%zu poses)\n", gtPath.c_str(), ev.groundTruthPoses);
  std::printf("estimate:     %s (%zu poses)\n", estPath.c_str(), ev.estimatePoses);
  if (ev.duplicateStampsDropped > 0)
    std::printf("note: %zu repeated timestamp(s) ignored (last line of a stamp wins)\n",
                ev.duplicateStampsDropped);
  if (opt.interpolate)
    std::printf("pairs with ground truth interpolated: %zu\n", ev.pairs);
  else
    std::printf("pairs associated (|dt| < %g s):       %zu\n", opt.maxDifference, ev.pairs);
  std::printf("estimated poses without gt partner:   %zu\n", ev.unmatchedEstimatePoses);
  std::printf("ATE (rigid alignment, no scale):\n");
  std::printf("  rmse   %.6f m\n  mean   %.6f m\n  median %.6f m\n", a.rmse, a.mean, a.median);
  std::printf("  std    %.6f m\n  min    %.6f m\n  max    %.6f m\n", a.std, a.min, a.max);
  if (!r.valid) {
    std::printf("RPE over %g s: not available: %s\n", r.delta, r.reason.c_str());
    return;
  }
  // With the default delta of 1 s the errors per interval are per-second drift.
  const std::string per = r.delta == 1.0 ? "/s" : " per " + jsonNumber(r.delta) + " s";
  std::printf("RPE over %g s (%zu pose pairs):\n", r.delta, r.pairs);
  std::printf("  translational rmse %.6f m%s, mean %.6f m%s, median %.6f m%s, max %.6f m%s\n",
              r.translation.rmse, per.c_str(), r.translation.mean, per.c_str(),
              r.translation.median, per.c_str(), r.translation.max, per.c_str());
  std::printf(
      "  rotational    rmse %.6f deg%s, mean %.6f deg%s, median %.6f deg%s, max %.6f deg%s\n",
      r.rotationDegrees.rmse, per.c_str(), r.rotationDegrees.mean, per.c_str(),
      r.rotationDegrees.median, per.c_str(), r.rotationDegrees.max, per.c_str());
  auto scale = [](double v) { return std::isfinite(v) ? jsonNumber(v) : std::string("n/a"); };
  std::printf("  rotation scale (estimate / ground truth) about x %s, y %s, z %s\n",
              scale(r.rotationScale.x()).c_str(), scale(r.rotationScale.y()).c_str(),
              scale(r.rotationScale.z()).c_str());
}

/// readTumTrajectory's messages already name FILE:LINE; we add which input it was, and check
/// existence first so a wrong path reads as such.
Trajectory load(const std::string& role, const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw std::runtime_error(role + " file '" + path + "' does not exist");
  if (std::filesystem::is_directory(path, ec))
    throw std::runtime_error(role + " path '" + path + "' is a directory, not a trajectory file");
  Trajectory traj;
  try {
    traj = readTumTrajectory(path);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read " + role + " trajectory: " + e.what());
  }
  if (traj.empty()) throw std::runtime_error(role + " file '" + path + "' contains no poses");
  return traj;
}

}  // namespace

int main(int argc, char** argv) {
  return slamdunk::runTool("evaluate-trajectory", [&] {
    TCLAP::CmdLine cmd(kDescription, ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> gtArg(
        "GROUNDTRUTH", "Ground-truth trajectory (TUM format).", true, "", "GROUNDTRUTH.txt", cmd);
    TCLAP::UnlabeledValueArg<std::string> estArg("ESTIMATE", "Estimated trajectory (TUM format).",
                                                 true, "", "ESTIMATE.txt", cmd);
    TCLAP::SwitchArg jsonArg("", "json", "Print one JSON object on stdout instead of text.", cmd);
    TCLAP::ValueArg<double> maxDtArg(
        "", "max-dt",
        "Largest timestamp difference (s, exclusive) for pairing an estimated pose with a "
        "ground-truth pose for ATE (associate.py's --max_difference). Default 0.02.",
        false, 0.02, "seconds", cmd);
    TCLAP::ValueArg<double> rpeDeltaArg(
        "", "rpe-delta",
        "Time between the two poses of each RPE pair (evaluate_rpe.py's --delta with "
        "--delta_unit s). Default 1.0, giving m/s and deg/s. RPE pairs ground truth to "
        "estimated stamps within 2x the median ground-truth interval, as evaluate_rpe.py does.",
        false, 1.0, "seconds", cmd);
    TCLAP::ValueArg<double> offsetArg("", "offset",
                                      "Time offset added to the estimated stamps (s). Default 0.",
                                      false, 0.0, "seconds", cmd);

    TCLAP::SwitchArg interpolateArg(
        "", "interpolate",
        "Compare each estimated pose with the ground truth interpolated at its stamp (plus "
        "--offset) between the two poses around it (position linearly, rotation by slerp), when "
        "those are at most 2x --max-dt apart, instead of the nearest ground-truth pose: for time "
        "offsets finer than the ground truth's rate. Not the TUM scripts' ATE.",
        cmd);

    if (const auto exitCode = parseCommandLine(cmd, argc, argv, "evaluate-trajectory"))
      return *exitCode;

    EvaluationOptions options;
    options.maxDifference = maxDtArg.getValue();
    options.rpeDelta = rpeDeltaArg.getValue();
    options.offset = offsetArg.getValue();
    options.interpolate = interpolateArg.getValue();
    if (!(options.maxDifference > 0) || !std::isfinite(options.maxDifference))
      throw std::runtime_error("--max-dt must be a positive number of seconds");
    if (!(options.rpeDelta > 0) || !std::isfinite(options.rpeDelta))
      throw std::runtime_error("--rpe-delta must be a positive number of seconds");
    if (!std::isfinite(options.offset)) throw std::runtime_error("--offset must be finite");

    const std::string gtPath = gtArg.getValue(), estPath = estArg.getValue();
    const Trajectory gt = load("ground-truth", gtPath);
    const Trajectory est = load("estimated", estPath);
    const TrajectoryEvaluation ev = TrajectoryMetrics::evaluate(gt, est, options);

    if (jsonArg.getValue())
      printJson(gtPath, estPath, options, ev);
    else
      printHuman(gtPath, estPath, options, ev);
    return 0;
  });
}
