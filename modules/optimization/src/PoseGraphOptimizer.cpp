#include <slamdunk/core/Stopwatch.h>
#include <slamdunk/optimization/PoseGraphOptimizer.h>

#include "LocalProblem.h"
#include "PoseParameters.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Geometry>

#include <map>
#include <set>

namespace slamdunk {

namespace {

/// r = (t_ij − t_meas) / σ_t and 2 vec(q_meas⁻¹ q_ij) / σ_r, with T_ij = T_i⁻¹ T_j in i's frame.
struct RelativePoseResidual {
  RelativePoseResidual(const Pose& measured, const PoseGraphOptions& o)
      : q(Eigen::Quaterniond(measured.linear()).normalized()),
        t(measured.translation()),
        translationScale(1.0 / o.translationSigma),
        rotationScale(2.0 / o.rotationSigma) {}

  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* qj, const T* tj, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> Qi(qi), Qj(qj);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> Ti(ti), Tj(tj);
    const Eigen::Quaternion<T> QiInverse = Qi.conjugate();
    const Eigen::Matrix<T, 3, 1> tij = QiInverse * (Tj - Ti);
    const Eigen::Quaternion<T> error = q.cast<T>().conjugate() * (QiInverse * Qj);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = (tij - t.cast<T>()) * T(translationScale);
    r.template tail<3>() = error.vec() * T(rotationScale);
    return true;
  }

  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  double translationScale, rotationScale;
};

/// The anchored keyframes, and the smallest id of each connected component (edges and loops
/// together) that holds none: LocalProblem's rule.
std::set<KeyframeId> gaugeVertices(const std::map<KeyframeId, Pose>& poses,
                                   const std::vector<std::pair<KeyframeId, KeyframeId>>& links,
                                   const std::set<KeyframeId>& anchored) {
  LocalProblem components;
  components.poses = poses;
  for (KeyframeId id : anchored)
    if (poses.count(id)) components.fixed.insert(id);
  for (const auto& [i, j] : links) components.edges.push_back({i, j, {}});
  fixGauge(components, nullptr);
  return components.fixed;
}
}  // namespace

PoseGraphReport optimizePoseGraph(KeyframeGraph& graph,
                                  const std::vector<RelativePoseConstraint>& loops,
                                  const PoseGraphOptions& options) {
  const auto t0 = SteadyClock::now();
  PoseGraphReport report;
  const std::map<KeyframeId, Pose> poses = graph.poses();
  std::vector<RelativePoseConstraint> constraints;
  std::vector<std::pair<KeyframeId, KeyframeId>> links;
  for (const auto& [i, j] : graph.edgeIds()) {
    constraints.push_back({i, j, poses.at(i).inverse() * poses.at(j)});
    links.emplace_back(i, j);
  }
  for (const RelativePoseConstraint& c : loops) {
    if (!poses.count(c.i) || !poses.count(c.j)) {
      report.message = "a loop names a keyframe the graph does not hold";
      return report;
    }
    constraints.push_back(c);
    links.emplace_back(c.i, c.j);
  }
  report.vertices = poses.size();
  if (poses.empty()) {
    report.message = "no keyframe";
    return report;
  }
  report.constraints = constraints.size();

  PoseParameters parameters(poses, gaugeVertices(poses, links, graph.anchoredIds()));
  ceres::Problem::Options problemOptions;
  problemOptions.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problemOptions);
  parameters.addTo(problem);
  for (const RelativePoseConstraint& c : constraints)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 4, 3, 4, 3>(
                                 new RelativePoseResidual(c.T_i_j, options)),
                             nullptr, parameters.quaternion(c.i), parameters.translation(c.i),
                             parameters.quaternion(c.j), parameters.translation(c.j));

  ceres::Solver::Options solverOptions;
  solverOptions.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solverOptions.max_num_iterations = options.maxIterations;
  solverOptions.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solverOptions, &problem, &summary);
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initialCost = summary.initial_cost;
  report.finalCost = summary.final_cost;
  if (!summary.IsSolutionUsable()) {
    report.message = "solver failed: " + summary.message;
    report.timeMs = msSince(t0);
    return report;
  }
  const std::map<KeyframeId, Pose> moved = parameters.freePoses();
  for (const auto& [id, pose] : moved) {
    if (!isValidPose(pose)) {
      report.message = "solver returned an invalid pose for keyframe " + std::to_string(id);
      report.timeMs = msSince(t0);
      return report;
    }
    report.maxTranslationChange =
        std::max(report.maxTranslationChange, translationDistance(poses.at(id), pose));
  }
  // The newest keyframe it moved, not the snapshot's newest: that one may have been caught
  // before its edges (a lone vertex, held as its own gauge) and must move with its neighbours.
  if (!moved.empty()) graph.applyCorrection(moved, moved.rbegin()->first);
  report.usable = true;
  report.message = summary.BriefReport();
  report.timeMs = msSince(t0);
  return report;
}

}  // namespace slamdunk
