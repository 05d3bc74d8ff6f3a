#pragma once
// Solves a LocalProblem (a copy: no graph lock is held here). Two equivalent formulations of
// paper Eq. 4:
//  - edge form (default): one EdgeMomentResidual per edge; robust losses by iteratively
//    reweighted least squares (each round is an exact weighted least-squares solve, which for
//    Huber/Cauchy never increases the robust cost);
//  - match form: one PointMatchResidual per match with the robust loss inside Ceres. Slower; the
//    textbook form, kept as the reference the edge form is tested against.

#include "LocalProblem.h"

#include <slamdunk/optimization/LocalOptimizer.h>

#include <ceres/loss_function.h>
#include <ceres/solver.h>

#include <map>
#include <memory>
#include <string>

namespace slamdunk {

struct BundleAdjustmentResult {
  std::map<KeyframeId, Pose> freePoses;   ///< optimised values of the free vertices
  PointRefinements refinedPoints;         ///< landmark form: the features' optimised positions
  double initialCost = 0, finalCost = 0;  ///< Σ w ρ(‖e‖²) (ρ(s) = s without robust loss)
  int iterations = 0;                     ///< Levenberg-Marquardt iterations over all rounds
  int rounds = 0;                         ///< reweighting rounds (1 without robust loss)
  int landmarks = 0;                      ///< landmark form: landmarks optimised
  int observations = 0;                   ///< landmark form: their observations
  bool converged = false;
  bool usable = false;
  std::string message;
};

class BundleAdjuster {
 public:
  explicit BundleAdjuster(const LocalOptimizerOptions& options);
  BundleAdjustmentResult solve(const LocalProblem& problem) const;

 private:
  BundleAdjustmentResult solveEdgeForm(const LocalProblem& problem) const;
  BundleAdjustmentResult solveMatchForm(const LocalProblem& problem) const;
  BundleAdjustmentResult solveLandmarkForm(const LocalProblem& problem) const;
  ceres::Solver::Options solverOptions() const;
  /// Σ w ρ(‖e‖²) with the free vertices at `freePoses` and the fixed ones at their snapshot.
  double cost(const LocalProblem& problem, const std::map<KeyframeId, Pose>& freePoses) const;
  /// Per-match weights of one reweighting round: w ρ'(‖e‖²) at the given poses.
  std::vector<std::vector<double>> irlsWeights(const LocalProblem& problem,
                                               const std::map<KeyframeId, Pose>& freePoses) const;

  LocalOptimizerOptions options_;
  std::unique_ptr<ceres::LossFunction> rho_;  // null: plain least squares (the paper)
};

}  // namespace slamdunk
