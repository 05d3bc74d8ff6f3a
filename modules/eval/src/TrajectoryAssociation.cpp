#include <slamdunk/eval/TrajectoryAssociation.h>

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

struct Candidate {
  double diff;
  std::size_t gt, est;
};

}  // namespace

TrajectoryAssociation TrajectoryAssociation::compute(const Trajectory& gt, const Trajectory& est,
                                                     double maxDifference, double offset) {
  const std::vector<std::size_t> estOrder = indicesSortedByStamp(est);
  std::vector<double> estShifted(estOrder.size());
  for (std::size_t k = 0; k < estOrder.size(); ++k)
    estShifted[k] = est[estOrder[k]].timestamp + offset;

  // Same candidate set as associate.py's all-pairs loop, but only scanning the estimate stamps
  // near each ground-truth stamp. The window is deliberately wider than maxDifference; the exact
  // test below (same floating-point expression as the script) decides.
  std::vector<Candidate> candidates;
  for (std::size_t g = 0; g < gt.size(); ++g) {
    const double a = gt[g].timestamp;
    auto it = std::lower_bound(estShifted.begin(), estShifted.end(), a - 2 * maxDifference);
    for (; it != estShifted.end() && *it <= a + 2 * maxDifference; ++it) {
      const double diff = std::abs(a - *it);
      if (diff < maxDifference) candidates.push_back({diff, g, estOrder[it - estShifted.begin()]});
    }
  }

  // Python sorts (diff, a, b) tuples: ties on the difference go to the smaller stamps.
  std::sort(candidates.begin(), candidates.end(), [&](const Candidate& l, const Candidate& r) {
    return std::make_tuple(l.diff, gt[l.gt].timestamp, est[l.est].timestamp, l.gt, l.est) <
           std::make_tuple(r.diff, gt[r.gt].timestamp, est[r.est].timestamp, r.gt, r.est);
  });

  TrajectoryAssociation result;
  std::vector<bool> gtTaken(gt.size(), false), estTaken(est.size(), false);
  for (const Candidate& c : candidates) {
    if (gtTaken[c.gt] || estTaken[c.est]) continue;
    gtTaken[c.gt] = estTaken[c.est] = true;
    result.pairs.push_back({c.gt, c.est});
  }
  std::sort(result.pairs.begin(), result.pairs.end(),
            [&](const AssociatedPair& l, const AssociatedPair& r) {
              return std::make_pair(gt[l.gt].timestamp, est[l.est].timestamp) <
                     std::make_pair(gt[r.gt].timestamp, est[r.est].timestamp);
            });
  result.unmatchedEstimates = est.size() - result.pairs.size();
  return result;
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
