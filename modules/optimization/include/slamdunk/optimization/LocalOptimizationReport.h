#pragma once
// What one call of LocalOptimizer::optimize()/optimizeAll() did, for logs and tests.

#include <slamdunk/graph/Keyframe.h>

#include <string>

namespace slamdunk {

struct LocalOptimizationReport {
  enum class Status {
    NothingToOptimise,  ///< no usable edge with a free endpoint: graph unchanged
    Optimised,          ///< solved and the free poses were written back
    Failed              ///< the solver failed or produced invalid poses: graph unchanged
  };

  Status status = Status::NothingToOptimise;
  KeyframeId root = 0;
  int verticesOptimised = 0;  ///< free poses in the problem
  int verticesFixed = 0;      ///< constant poses in the problem (outer ring, or the gauge vertex)
  int edges = 0;              ///< keyframe pairs contributing at least one residual
  int residuals = 0;          ///< point matches in the problem
  int landmarks = 0;          ///< landmark form: landmarks optimised with the poses
  int observations = 0;       ///< landmark form: their observations (residuals of 3)
  int invalidMatches = 0;     ///< skipped: non-finite point or weight, or negative weight
  int droppedMatches = 0;     ///< skipped: weight zero or below LocalOptimizerOptions::minWeight
  /// Σ w ρ(‖e‖²) over the residuals (paper Eq. 4 when the robust loss is "none").
  double initialCost = 0;
  double finalCost = 0;
  int iterations = 0;  ///< Levenberg-Marquardt iterations (over all reweighting rounds)
  int rounds = 0;      ///< reweighting rounds (1 without robust loss or in the match form)
  double timeMs = 0;   ///< wall time of the whole call (selection, assembly, solve, write-back)
  double maxTranslationChange = 0;  ///< metres, largest over the written-back poses
  double maxRotationChangeDeg = 0;  ///< degrees, largest over the written-back poses
  bool converged = false;           ///< the solver met a tolerance (not merely the iteration cap)
  bool usable = false;              ///< poses were written back to the graph
  std::string message;  ///< why nothing was done / why it failed, or the solver's verdict

  /// One line for logs.
  std::string toString() const;
};

}  // namespace slamdunk
