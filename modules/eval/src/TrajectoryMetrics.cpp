#include <slamdunk/eval/TrajectoryMetrics.h>

#include <slamdunk/core/Pose.h>
#include <slamdunk/core/Statistics.h>
#include <slamdunk/eval/RotationScale.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace slamdunk::eval {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

template <typename... Args>
std::string format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

/// evaluate_rpe.py's find_closest_index, step for step: a binary search that remembers the
/// closest element it visits. On a sorted list it visits both neighbours of t, so it returns the
/// closest element; on an exact tie it keeps the one visited first. Reproducing the visiting order
/// keeps tie-breaks (which happen with regular stamps and a round delta) identical to the script.
std::size_t findClosestIndex(const std::vector<double>& list, double t) {
  std::size_t begin = 0, end = list.size(), best = 0;
  double difference = std::abs(list[0] - t);
  while (begin < end) {
    const std::size_t middle = (begin + end) / 2;
    if (std::abs(list[middle] - t) < difference) {
      difference = std::abs(list[middle] - t);
      best = middle;
    }
    if (t == list[middle]) return middle;
    if (list[middle] > t)
      end = middle;
    else
      begin = middle + 1;
  }
  return best;
}

std::vector<double> stampsOf(const Trajectory& traj) {
  std::vector<double> stamps;
  stamps.reserve(traj.size());
  for (const StampedPose& p : traj) stamps.push_back(p.timestamp);
  return stamps;
}

}  // namespace

ErrorStatistics ErrorStatistics::compute(std::vector<double> values) {
  ErrorStatistics s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0, sumSq = 0;
  for (double v : values) {
    sum += v;
    sumSq += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sumSq / n);
  // Two-pass variance: numerically safer than sumSq/n - mean^2 for nearly constant errors.
  double var = 0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  std::sort(values.begin(), values.end());
  auto percentile = [&](double q) {
    const double rank = q / 100.0 * (n - 1);
    const std::size_t lo = static_cast<std::size_t>(rank);
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (rank - lo) * (values[hi] - values[lo]);
  };
  s.p95 = percentile(95);
  s.p99 = percentile(99);
  s.median = slamdunk::median(std::move(values));
  return s;
}

AteResult TrajectoryMetrics::computeAte(const Trajectory& gt, const Trajectory& est,
                                        const std::vector<AssociatedPair>& pairs) {
  if (pairs.empty())
    throw std::runtime_error(
        "ATE: no associated pose pairs (no estimated stamp is close enough "
        "to a ground-truth stamp)");
  if (pairs.size() < 3)
    throw std::runtime_error(
        "ATE: only " + std::to_string(pairs.size()) +
        " associated pose pair(s); aligning the trajectories needs at least 3");

  std::vector<Eigen::Vector3d> estPositions, gtPositions;
  for (const AssociatedPair& p : pairs) {
    estPositions.push_back(est.at(p.est).pose.translation());
    gtPositions.push_back(gt.at(p.gt).pose.translation());
  }

  AteResult result;
  result.alignment = RigidAlignment::compute(estPositions, gtPositions);
  for (std::size_t i = 0; i < pairs.size(); ++i)
    result.errors.push_back((result.alignment.apply(estPositions[i]) - gtPositions[i]).norm());
  result.stats = ErrorStatistics::compute(result.errors);
  return result;
}

// What evaluate_rpe.py does with --fixed_delta --delta <d> --delta_unit s, and what we copy:
//  - Pairs are built on the *estimate's* sorted stamps: for every i, j = the estimated stamp
//    closest to t_i + delta (find_closest_index). The pair is dropped when j is the last estimated
//    pose -- the script's way of discarding the end of the trajectory, where no stamp lies
//    delta later. It drops a genuine pair ending exactly on the last pose as well; we do the same
//    so the numbers match. j == i is not excluded (it can happen across a gap longer than 2 delta;
//    the error is then zero), again as in the script.
//  - Each estimated stamp is matched to the closest ground-truth stamp; a pair is skipped when
//    either end is more than 2 x (median ground-truth stamp interval) away. Note this is NOT
//    associate.py's 0.02 s window: the script uses this rule, so do we.
//  - error = (est_j^-1 est_i)^-1 (gt_j^-1 gt_i); translational error = |translation|, rotational
//    = rotation angle. Written this way round, not as (est_i^-1 est_j)^-1 (gt_i^-1 gt_j): the
//    angles agree but the translation norms do not when the estimate's rotation is off.
//  - Unlike the script we use all pairs (no random subsampling above --max_pairs 10000) and
//    report the rotational median in degrees (the script prints it in radians).
//  - Values are errors over delta seconds, not divided by delta (per second for delta = 1 s).
//  - Fewer than 2 compared pairs: the script raises; we return valid == false with a reason.
RpeResult TrajectoryMetrics::computeRpe(const Trajectory& gtIn, const Trajectory& estIn,
                                        double delta, double offset) {
  RpeResult result;
  result.delta = delta;
  const Trajectory gt = sortedUniqueByStamp(gtIn);
  const Trajectory est = sortedUniqueByStamp(estIn);
  if (!(delta > 0)) {
    result.reason = "RPE delta must be positive";
    return result;
  }
  if (gt.size() < 2 || est.size() < 2) {
    result.reason = "not enough poses: RPE needs at least 2 ground-truth and 2 estimated poses";
    return result;
  }

  const std::vector<double> gtStamps = stampsOf(gt);
  const std::vector<double> estStamps = stampsOf(est);
  std::vector<double> gtIntervals;
  for (std::size_t k = 1; k < gtStamps.size(); ++k)
    gtIntervals.push_back(gtStamps[k] - gtStamps[k - 1]);
  const double gtMaxTimeDifference = 2 * slamdunk::median(gtIntervals);

  std::vector<double> transErrors, rotErrors;
  RotationScale rotationScale;
  for (std::size_t i = 0; i < estStamps.size(); ++i) {
    const std::size_t j = findClosestIndex(estStamps, estStamps[i] + delta);
    if (j == estStamps.size() - 1) continue;

    const double t0 = estStamps[i] + offset, t1 = estStamps[j] + offset;
    const std::size_t g0 = findClosestIndex(gtStamps, t0);
    const std::size_t g1 = findClosestIndex(gtStamps, t1);
    if (std::abs(gtStamps[g0] - t0) > gtMaxTimeDifference ||
        std::abs(gtStamps[g1] - t1) > gtMaxTimeDifference)
      continue;

    const Pose relativeEst = est[j].pose.inverse() * est[i].pose;
    const Pose relativeGt = gt[g1].pose.inverse() * gt[g0].pose;
    const Pose error = relativeEst.inverse() * relativeGt;
    transErrors.push_back(error.translation().norm());
    rotErrors.push_back(rotationAngle(error) * kRadToDeg);
    rotationScale.add(relativeGt.linear(), relativeEst.linear());
  }

  result.pairs = transErrors.size();
  if (transErrors.size() < 2) {
    const double span = estStamps.back() - estStamps.front();
    if (span <= delta)
      result.reason = format(
          "not enough span: the estimate covers %.3f s, RPE needs pose pairs %.3f s apart "
          "(not ending on the last pose)",
          span, delta);
    else
      result.reason = format(
          "only %zu pose pair(s) %.3f s apart have ground truth within %.4f s of both poses "
          "(need 2)",
          transErrors.size(), delta, gtMaxTimeDifference);
    return result;
  }
  result.valid = true;
  result.rotationScale = rotationScale.scale();
  result.translation = ErrorStatistics::compute(std::move(transErrors));
  result.rotationDegrees = ErrorStatistics::compute(std::move(rotErrors));
  return result;
}

TrajectoryEvaluation TrajectoryMetrics::evaluate(const Trajectory& gtIn, const Trajectory& estIn,
                                                 const EvaluationOptions& options) {
  TrajectoryEvaluation out;
  std::size_t gtDuplicates = 0, estDuplicates = 0;
  Trajectory gt = sortedUniqueByStamp(gtIn, &gtDuplicates);
  const Trajectory est = sortedUniqueByStamp(estIn, &estDuplicates);
  out.groundTruthPoses = gt.size();
  out.estimatePoses = est.size();
  out.duplicateStampsDropped = gtDuplicates + estDuplicates;
  if (gt.empty()) throw std::runtime_error("the ground-truth trajectory has no poses");
  if (est.empty()) throw std::runtime_error("the estimated trajectory has no poses");
  if (options.interpolate) {
    // One ground-truth pose at each estimated instant: the association below pairs them exactly.
    std::vector<double> instants;
    for (const StampedPose& p : est) instants.push_back(p.timestamp + options.offset);
    const double first = gt.front().timestamp, last = gt.back().timestamp;
    gt = interpolatedAt(gt, instants, 2 * options.maxDifference);
    if (gt.empty())
      throw std::runtime_error(format(
          "no estimated stamp lies between two ground-truth poses at most %g s apart (ground "
          "truth spans %.6f..%.6f s, estimate spans %.6f..%.6f s); do both use the same clock?",
          2 * options.maxDifference, first, last, est.front().timestamp, est.back().timestamp));
  }

  const TrajectoryAssociation association =
      TrajectoryAssociation::compute(gt, est, options.maxDifference, options.offset);
  out.pairs = association.pairs.size();
  out.unmatchedEstimatePoses = association.unmatchedEstimates;
  if (association.pairs.empty())
    throw std::runtime_error(format(
        "no pose pairs associated: no estimated stamp lies within %g s of a ground-truth stamp "
        "(ground truth spans %.6f..%.6f s, estimate spans %.6f..%.6f s); do both use the same "
        "clock?",
        options.maxDifference, gt.front().timestamp, gt.back().timestamp, est.front().timestamp,
        est.back().timestamp));
  out.ate = computeAte(gt, est, association.pairs);
  out.rpe = computeRpe(gt, est, options.rpeDelta, options.offset);
  return out;
}

}  // namespace slamdunk::eval
