#pragma once
// The Ceres problem built from a LocalProblem: one parameter pair (unit quaternion on
// EigenQuaternionManifold, translation) per vertex and one 3-vector residual per point match.
// Assembly happens in the constructor; solve() runs the solver; poses() reads the result.

#include "LocalProblem.h"
#include "WeightedRobustLoss.h"

#include <slamdunk/optimization/LocalOptimizer.h>

#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <array>
#include <deque>
#include <map>
#include <memory>

namespace slamdunk {

class PoseProblem {
 public:
  PoseProblem(const LocalProblem& problem, const LocalOptimizerOptions& options);

  /// Levenberg-Marquardt with sparse Cholesky (SuiteSparse) on the normal equations.
  ceres::Solver::Summary solve(const LocalOptimizerOptions& options);
  /// Current values of the free vertices.
  std::map<KeyframeId, Pose> freePoses() const;

  int residualCount() const { return residuals_; }

 private:
  using Parameters = std::array<double, 7>;  // qx qy qz qw | tx ty tz
  static Parameters toParameters(const Pose& pose);
  static Pose toPose(const Parameters& x);
  ceres::LossFunction* makeLoss(double weight);

  // Declared before problem_ so that they outlive it (the problem does not own them).
  ceres::EigenQuaternionManifold quaternionManifold_;
  std::unique_ptr<ceres::LossFunction> robust_;    // shared ρ; null for the paper's plain cost
  std::deque<WeightedRobustLoss> weightedLosses_;  // one per residual, stable addresses
  std::map<KeyframeId, Parameters> parameters_;    // stable addresses for Ceres
  std::set<KeyframeId> fixed_;
  int residuals_ = 0;
  ceres::Problem problem_;
};

}  // namespace slamdunk
