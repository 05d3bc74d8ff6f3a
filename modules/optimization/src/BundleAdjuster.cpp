#include "BundleAdjuster.h"

#include <slamdunk/graph/LandmarkTracks.h>
#include "EdgeMomentResidual.h"
#include "LandmarkResidual.h"
#include "PointMatchResidual.h"
#include "PoseParameters.h"
#include "WeightedRobustLoss.h"

#include <ceres/problem.h>

#include <algorithm>
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

/// Takes a solved reweighting round's cost into `r`; true when the rounds are over. A plain
/// (not robust) cost needs one round; a robust one is settled once a round gains less than
/// `tolerance` of the cost, and is then converged whatever the solver said.
bool lastRound(BundleAdjustmentResult& r, double cost, double tolerance, bool robust,
               const ceres::Solver::Summary& summary) {
  const bool settled = r.finalCost - cost <= tolerance * r.finalCost;
  r.finalCost = cost;
  r.converged = summary.termination_type == ceres::CONVERGENCE;
  if (robust && !settled) return false;
  r.converged = r.converged || settled;
  return true;
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
  switch (options_.residualForm) {
    case ResidualForm::Edge:
      return solveEdgeForm(p);
    case ResidualForm::Match:
      return solveMatchForm(p);
    case ResidualForm::Landmarks:
      return solveLandmarkForm(p);
  }
  return {};
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
    current = std::move(next);
    if (lastRound(r, c, options_.functionTolerance, rho_ != nullptr, summary)) break;
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

namespace {
// Settled when a round gains less than 0.1 %: the weights then hardly change, and the poses
// move by far less than their noise (each round is a full solve: not for 1e-6).
constexpr double kLandmarkRoundsTolerance = 1e-3;
}  // namespace

BundleAdjustmentResult BundleAdjuster::solveLandmarkForm(const LocalProblem& p) const {
  BundleAdjustmentResult r;
  const DepthNoiseModel& noise = options_.noise;
  const LandmarkTracks tracks = buildLandmarkTracks(p.edges);
  ceres::Problem problem(problemOptions());
  PoseParameters params(p.poses, p.fixed);
  params.addTo(problem);

  // Every residual is whitened, and carries a weight of its own (a loss wrapper): the robust
  // loss is applied by reweighting rounds, each an exact weighted least-squares solve. Ceres'
  // own robust-loss correction made every step fall short (tens of iterations per solve).
  std::deque<ceres::LossFunctionWrapper> weights;
  std::vector<ceres::ResidualBlockId> blocks;
  auto add = [&](ceres::CostFunction* cost, std::vector<double*> blocksOf) {
    ceres::LossFunctionWrapper& w = weights.emplace_back(nullptr, ceres::TAKE_OWNERSHIP);
    blocks.push_back(problem.AddResidualBlock(cost, &w, blocksOf));
  };

  // A landmark starts at the precision-weighted mean of its observations in the world.
  std::vector<Eigen::Vector3d> positions;
  std::vector<const Landmark*> optimised;
  positions.reserve(tracks.landmarks.size());  // stable addresses for Ceres
  for (const Landmark& l : tracks.landmarks) {
    const bool seenByFree = std::any_of(l.observations.begin(), l.observations.end(),
                                        [&](const auto& o) { return p.isFree(o.keyframe); });
    if (!seenByFree) continue;  // constant: cannot move a free pose
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0;
    for (const LandmarkObservation& o : l.observations) {
      const double w = 1.0 / noise.variance(o.point.z());
      sum += w * (p.poses.at(o.keyframe) * o.point);
      total += w;
    }
    Eigen::Vector3d& x = positions.emplace_back(sum / total);
    optimised.push_back(&l);
    for (const LandmarkObservation& o : l.observations) {
      const Eigen::Vector2d& f = p.focalLengths.at(o.keyframe);
      add(LandmarkResidual::create(o.point, f.x(), f.y(), noise.pixelSigma,
                                   noise.depthSigma(o.point.z())),
          {params.quaternion(o.keyframe), params.translation(o.keyframe), x.data()});
      ++r.observations;
    }
  }
  r.landmarks = static_cast<int>(positions.size());
  // Matches of dense depth, whitened like the features: their weights are relative to a match
  // of two points 1 m away (the tracker's normalisation).
  const double unitVariance = 2 * noise.variance(1.0);
  for (const auto& [e, m] : tracks.pointMatches) {
    const KeyframeEdge& edge = p.edges[e];
    const PointMatch& match = edge.matches[m];
    add(PointMatchResidual::create(match.pointI, match.pointJ, match.weight / unitVariance,
                                   match.information),
        {params.quaternion(edge.i), params.translation(edge.i), params.quaternion(edge.j),
         params.translation(edge.j)});
  }
  if (blocks.empty()) {
    r.message = "no landmark seen by a free keyframe";
    return r;
  }

  // Huber on the whitened residual's norm: weight 1 within landmarkLossScale σ, a/‖e‖ beyond.
  const double a = options_.landmarkLossScale;
  const bool robust = options_.robustLoss != RobustLoss::None;
  auto robustCost = [&](bool reweight) {
    double total = 0;
    for (size_t b = 0; b < blocks.size(); ++b) {
      double cost = 0;  // ½ ‖e‖², without the weight
      problem.EvaluateResidualBlock(blocks[b], false, &cost, nullptr, nullptr);
      const double s = 2 * cost;
      const bool inlier = !robust || s <= a * a;
      total += inlier ? s : 2 * a * std::sqrt(s) - a * a;
      if (reweight)
        weights[b].Reset(
            inlier ? nullptr
                   : new ceres::ScaledLoss(nullptr, a / std::sqrt(s), ceres::TAKE_OWNERSHIP),
            ceres::TAKE_OWNERSHIP);
    }
    return total;
  };
  ceres::Solver::Options options = solverOptions();
  // Landmarks are eliminated first (Schur complement): the reduced system is the poses'.
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  r.initialCost = r.finalCost = robustCost(true);
  if (!std::isfinite(r.initialCost)) {
    r.message = "non-finite initial cost";
    return r;
  }
  const int maxRounds = robust ? options_.irlsMaxRounds : 1;
  for (r.rounds = 1; r.rounds <= maxRounds; ++r.rounds) {
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    r.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    r.message = summary.message;
    if (!summary.IsSolutionUsable()) return r;
    const double cost = robustCost(true);
    if (!std::isfinite(cost)) {
      r.message = "non-finite cost after solving: " + summary.message;
      return r;
    }
    if (lastRound(r, cost, kLandmarkRoundsTolerance, robust, summary)) break;
  }
  r.rounds = std::min(r.rounds, maxRounds);
  r.freePoses = params.freePoses();
  // Each observation's feature moves to where its landmark ended up, seen from its keyframe.
  for (size_t n = 0; n < optimised.size(); ++n)
    for (const LandmarkObservation& o : optimised[n]->observations) {
      if (!positions[n].allFinite()) continue;
      const Pose& pose = poseOf(p, r.freePoses, o.keyframe);
      r.refinedPoints[o.keyframe].emplace_back(o.feature, pose.inverse() * positions[n]);
    }
  r.usable = true;
  return r;
}

}  // namespace slamdunk
