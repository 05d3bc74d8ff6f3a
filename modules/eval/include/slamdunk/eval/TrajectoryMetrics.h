#pragma once
// Absolute trajectory error (evaluate_ate.py) and relative pose error (evaluate_rpe.py with
// --fixed_delta --delta_unit s, over all pairs) of an estimated trajectory against ground truth.

#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/eval/RigidAlignment.h>
#include <slamdunk/eval/RotationScale.h>
#include <slamdunk/eval/TrajectoryAssociation.h>

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace slamdunk::eval {

/// Summary of a list of non-negative errors, with numpy's conventions: median of an even count
/// is the mean of the two middle values, std is the population standard deviation.
struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
  double p95 = 0, p99 = 0;  ///< percentiles, interpolated linearly between ranks (numpy's)

  /// All zeros for an empty list.
  static ErrorStatistics compute(std::vector<double> values);
};

struct AteResult {
  RigidAlignment alignment;    ///< maps estimated positions onto ground-truth positions
  std::vector<double> errors;  ///< metres, one per associated pair, in association order
  ErrorStatistics stats;       ///< metres
};

struct RpeResult {
  /// False when no statistics could be computed; `reason` then says why (e.g. not enough span).
  bool valid = false;
  std::string reason;
  double delta = 1.0;               ///< seconds between the two poses of each compared pair
  std::size_t pairs = 0;            ///< compared pose pairs
  ErrorStatistics translation;      ///< metres per delta
  ErrorStatistics rotationDegrees;  ///< degrees per delta
  /// Per camera axis (x right, y down, z forward): how much the estimate turns for each turn of
  /// the ground truth over the same pairs (RotationScale, the ground truth as the reference).
  /// NaN for an axis the ground truth turns about by less than kMinRotationForScaleDegrees.
  Eigen::Vector3d rotationScale =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  static constexpr double kMinRotationForScaleDegrees = RotationScale::kMinRotationDegrees;
};

struct EvaluationOptions {
  double maxDifference = 0.02;  ///< association window for ATE, seconds
  double offset = 0.0;          ///< added to estimate stamps before comparing them, seconds
  double rpeDelta = 1.0;        ///< seconds
  /// Compare each estimated pose with the ground truth interpolated at its stamp (plus offset)
  /// between the poses around it, at most 2 x maxDifference apart (interpolatedAt), instead of
  /// the nearest ground-truth pose.
  bool interpolate = false;
};

struct TrajectoryEvaluation {
  std::size_t groundTruthPoses = 0;        ///< distinct stamps
  std::size_t estimatePoses = 0;           ///< distinct stamps
  std::size_t duplicateStampsDropped = 0;  ///< over both inputs (last line of a stamp wins)
  std::size_t pairs = 0;                   ///< associated (gt, estimate) pairs used by ATE
  std::size_t unmatchedEstimatePoses = 0;  ///< estimated poses without a ground-truth partner
  AteResult ate;
  RpeResult rpe;
};

class TrajectoryMetrics {
 public:
  /// ATE over already associated pairs: aligns the estimated positions onto the ground-truth
  /// positions (rotation + translation, no scale) and measures the remaining position errors.
  /// Throws std::runtime_error with fewer than 3 pairs (no pair at all gets its own message).
  static AteResult computeAte(const Trajectory& gt, const Trajectory& est,
                              const std::vector<AssociatedPair>& pairs);

  /// RPE over `delta` seconds. Never throws for lack of data: returns valid == false with a reason
  /// (fewer than 2 poses, estimate shorter than delta, no usable pairs).
  static RpeResult computeRpe(const Trajectory& gt, const Trajectory& est, double delta = 1.0,
                              double offset = 0.0);

  /// Both metrics the way the TUM scripts run them on two files: inputs reduced to sorted distinct
  /// stamps, ATE on the associate.py pairs, RPE on the estimate's own stamps. Throws like
  /// computeAte.
  static TrajectoryEvaluation evaluate(const Trajectory& gt, const Trajectory& est,
                                       const EvaluationOptions& options = {});
};

}  // namespace slamdunk::eval
