#include <slamdunk/core/TimestampAssociation.h>
#include <slamdunk/eval/TrajectoryAssociation.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace slamdunk::eval {

namespace {

std::vector<std::size_t> indicesSortedByStamp(const Trajectory& traj) {
  std::vector<std::size_t> order(traj.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return traj[a].timestamp < traj[b].timestamp;
  });
  return order;
}

}  // namespace

TrajectoryAssociation TrajectoryAssociation::compute(const Trajectory& gt, const Trajectory& est,
                                                     double maxDifference, double offset) {
  std::vector<double> gtStamps, estStamps;
  for (const auto& p : gt) gtStamps.push_back(p.timestamp);
  for (const auto& p : est) estStamps.push_back(p.timestamp);
  TrajectoryAssociation result;
  for (const auto& [g, e] : associateTimestamps(gtStamps, estStamps, maxDifference, offset))
    result.pairs.push_back({g, e});
  result.unmatchedEstimates = est.size() - result.pairs.size();
  return result;
}

Trajectory interpolatedAt(const Trajectory& sortedGt, const std::vector<double>& stamps,
                          double maxGap) {
  Trajectory out;
  for (const double t : stamps) {
    const auto after =
        std::lower_bound(sortedGt.begin(), sortedGt.end(), t,
                         [](const StampedPose& p, double stamp) { return p.timestamp < stamp; });
    if (after == sortedGt.end()) continue;
    if (after->timestamp == t) {
      out.push_back({t, after->pose});
      continue;
    }
    if (after == sortedGt.begin()) continue;
    const StampedPose& before = *std::prev(after);
    if (after->timestamp - before.timestamp > maxGap) continue;
    const double a = (t - before.timestamp) / (after->timestamp - before.timestamp);
    Pose pose = Pose::Identity();
    pose.translation() = (1 - a) * before.pose.translation() + a * after->pose.translation();
    pose.linear() = Eigen::Quaterniond(before.pose.linear())
                        .slerp(a, Eigen::Quaterniond(after->pose.linear()))
                        .toRotationMatrix();
    out.push_back({t, pose});
  }
  return out;
}

Trajectory sortedUniqueByStamp(const Trajectory& traj, std::size_t* duplicatesDropped) {
  Trajectory out;
  out.reserve(traj.size());
  for (std::size_t i : indicesSortedByStamp(traj)) {
    // Stable sort keeps file order within equal stamps, so overwriting keeps the last line.
    if (!out.empty() && out.back().timestamp == traj[i].timestamp)
      out.back() = traj[i];
    else
      out.push_back(traj[i]);
  }
  if (duplicatesDropped) *duplicatesDropped = traj.size() - out.size();
  return out;
}

}  // namespace slamdunk::eval
