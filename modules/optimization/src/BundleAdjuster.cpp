#include "BundleAdjuster.h"

#include "EdgeMomentResidual.h"
#include "PointMatchResidual.h"
#include "PoseParameters.h"
#include "WeightedRobustLoss.h"

#include <ceres/problem.h>

#include <cmath>
#include <deque>

namespace slamdunk {

namespace {
std::unique_ptr<ceres::LossFunction> makeRho(const LocalOptimizerOptions& o) {
  // Ceres' scale a acts on s = ‖e‖²: Huber and Cauchy bend where ‖e‖ ≈ a (metres).
  switch (o.robustLoss) {
    case RobustLoss::None:
      return nullptr;
    case RobustLoss::Huber:
      return std::make_unique<ceres::HuberLoss>(o.robustLossScale);
    case RobustLoss::Cauchy:
      return std::make_unique<ceres::CauchyLoss>(o.robustLossScale);
  }
  return nullptr;
}

ceres::Problem::Options problemOptions() {
  ceres::Problem::Options o;
  // Manifolds and losses belong to PoseParameters / the solver; cost functions to Ceres.
  o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return o;
}

/// Pose of a vertex: optimised value if free, snapshot value otherwise.
const Pose& poseOf(const LocalProblem& p, const std::map<KeyframeId, Pose>& freePoses,
                   KeyframeId id) {
  const auto it = freePoses.find(id);
  return it != freePoses.end() ? it->second : p.poses.at(id);
}
}  // namespace

BundleAdjuster::BundleAdjuster(const LocalOptimizerOptions& options)
    : options_(options), rho_(makeRho(options)) {}

ceres::Solver::Options BundleAdjuster::solverOptions() const {
  ceres::Solver::Options s;
  s.minimizer_type = ceres::TRUST_REGION;
  s.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  s.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  s.max_num_iterations = options_.maxIterations;
  s.function_tolerance = options_.functionTolerance;
  s.num_threads = options_.numThreads;
  if (options_.maxSolverTimeMs > 0) s.max_solver_time_in_seconds = options_.maxSolverTimeMs / 1e3;
  s.minimizer_progress_to_stdout = false;
  s.logging_type = ceres::SILENT;
  return s;
}

double BundleAdjuster::cost(const LocalProblem& p,
                            const std::map<KeyframeId, Pose>& freePoses) const {
  double total = 0;
  for (const KeyframeEdge& e : p.edges) {
    const Pose rel = poseOf(p, freePoses, e.i).inverse() * poseOf(p, freePoses, e.j);
    for (const PointMatch& m : e.matches) {
      const double s = m.squaredError(rel);
      double rho[3] = {s, 1, 0};
      if (rho_) rho_->Evaluate(s, rho);
      total += m.weight * rho[0];
    }
  }
  return total;
}

std::vector<std::vector<double>> BundleAdjuster::irlsWeights(
    const LocalProblem& p, const std::map<KeyframeId, Pose>& freePoses) const {
  std::vector<std::vector<double>> weights;
  weights.reserve(p.edges.size());
  for (const KeyframeEdge& e : p.edges) {
    const Pose rel = poseOf(p, freePoses, e.i).inverse() * poseOf(p, freePoses, e.j);
    std::vector<double>& w = weights.emplace_back();
    w.reserve(e.matches.size());
    for (const PointMatch& m : e.matches) {
      double rho[3] = {0, 1, 0};
      if (rho_) rho_->Evaluate(m.squaredError(rel), rho);
      w.push_back(m.weight * rho[1]);  // d/ds of w ρ(s): the weight of the quadratic majoriser
    }
  }
  return weights;
}

BundleAdjustmentResult BundleAdjuster::solve(const LocalProblem& p) const {
  std::string why;
  if (!solverOptions().IsValid(&why)) {  // e.g. Ceres built without SuiteSparse
    BundleAdjustmentResult r;
    r.message = "invalid solver options: " + why;
    return r;
  }
  return options_.residualForm == ResidualForm::Edge ? solveEdgeForm(p) : solveMatchForm(p);
}

BundleAdjustmentResult BundleAdjuster::solveEdgeForm(const LocalProblem& p) const {
  BundleAdjustmentResult r;
  std::map<KeyframeId, Pose> current;
  for (const auto& [id, pose] : p.poses)
    if (!p.fixed.count(id)) current.emplace(id, pose);
  r.initialCost = r.finalCost = cost(p, current);
  if (!std::isfinite(r.initialCost)) {
    r.message = "non-finite initial cost (absurd point coordinates?)";
    return r;
  }
  const int maxRounds = rho_ ? options_.irlsMaxRounds : 1;
  for (r.rounds = 1; r.rounds <= maxRounds; ++r.rounds) {
    const auto weights = irlsWeights(p, current);
    ceres::Problem problem(problemOptions());
    PoseParameters params(p.poses, p.fixed);
    params.setFree(current);
    params.addTo(problem);
    for (size_t n = 0; n < p.edges.size(); ++n) {
      const KeyframeEdge& e = p.edges[n];
      problem.AddResidualBlock(EdgeMomentResidual(e.matches, weights[n]).toCostFunction(), nullptr,
                               params.quaternion(e.i), params.translation(e.i),
                               params.quaternion(e.j), params.translation(e.j));
    }
    ceres::Solver::Summary summary;
    ceres::Solve(solverOptions(), &problem, &summary);
    r.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    r.message = summary.message;
    if (!summary.IsSolutionUsable()) return r;

    auto next = params.freePoses();
    const double c = cost(p, next);
    if (!std::isfinite(c)) {
      r.message = "non-finite cost after solving: " + summary.message;
      return r;
    }
    if (c > r.finalCost) {  // an inexact round made things worse: keep the previous poses
      r.converged = true;
      break;
    }
    const bool settled = r.finalCost - c <= options_.functionTolerance * r.finalCost;
    current = std::move(next);
    r.finalCost = c;
    r.converged = summary.termination_type == ceres::CONVERGENCE;
    if (!rho_ || settled) {
      r.converged = r.converged || settled;
      break;
    }
  }
  r.rounds = std::min(r.rounds, maxRounds);
  r.freePoses = std::move(current);
  r.usable = true;
  return r;
}

BundleAdjustmentResult BundleAdjuster::solveMatchForm(const LocalProblem& p) const {
  BundleAdjustmentResult r;
  r.rounds = 1;
  ceres::Problem problem(problemOptions());
  PoseParameters params(p.poses, p.fixed);
  params.addTo(problem);
  std::deque<WeightedRobustLoss> losses;  // one per match, stable addresses
  for (const KeyframeEdge& e : p.edges) {
    for (const PointMatch& m : e.matches) {
      ceres::LossFunction* loss = rho_ ? &losses.emplace_back(rho_.get(), m.weight) : nullptr;
      problem.AddResidualBlock(
          PointMatchResidual::create(m.pointI, m.pointJ, m.weight, m.information), loss,
          params.quaternion(e.i), params.translation(e.i), params.quaternion(e.j),
          params.translation(e.j));
    }
  }
  ceres::Solver::Summary summary;
  ceres::Solve(solverOptions(), &problem, &summary);
  r.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  r.converged = summary.termination_type == ceres::CONVERGENCE;
  r.message = summary.message;
  // Ceres' cost is ½ Σ; reported as Σ like the edge form.
  r.initialCost = 2 * summary.initial_cost;
  r.finalCost = 2 * summary.final_cost;
  if (!summary.IsSolutionUsable() || !std::isfinite(r.finalCost)) return r;
  r.freePoses = params.freePoses();
  r.usable = true;
  return r;
}

}  // namespace slamdunk
