#pragma once
// Relative bundle adjustment of keyframe poses (paper Sec. 4.3, Eq. 4-5): minimises
// Σ w ‖p_i − T_i⁻¹ T_j p_j‖² over the point matches of the keyframes within R rings of a root.
// Ceres is an implementation detail: this header does not include it.

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/EnumNames.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/optimization/LocalOptimizationReport.h>

#include <mrpt/config/CLoadableOptions.h>

#include <string>

namespace slamdunk {

enum class RobustLoss { None, Huber, Cauchy };

SLAMDUNK_ENUM_NAMES(RobustLoss, {{RobustLoss::None, "none"},
                                 {RobustLoss::Huber, "huber"},
                                 {RobustLoss::Cauchy, "cauchy"}});

/// The cost the local optimization minimises. Edge and match are paper Eq. 4 (3D-3D point
/// differences): edge, one residual per edge built from the matches' weighted moments (same
/// minimiser and Gauss-Newton steps, cost independent of the match count; robust losses by
/// reweighting rounds); match, one residual per match (textbook form, slower). Landmarks goes
/// beyond the paper: the feature matches are followed from keyframe to keyframe into landmarks
/// (one 3D point per scene point, optimised too), each observed in pixels and depth with the
/// features' own precisions (LandmarkResidual).
enum class ResidualForm { Edge, Match, Landmarks };
SLAMDUNK_ENUM_NAMES(ResidualForm, {{ResidualForm::Edge, "edge"},
                                   {ResidualForm::Match, "match"},
                                   {ResidualForm::Landmarks, "landmarks"}});

struct LocalOptimizerOptions : public mrpt::config::CLoadableOptions {
  int rings = 3;  ///< R (paper Table 3): rings 0..R-1 are free, ring R is held fixed
  /// Huber by default: RANSAC-filtered matches are mostly within ~2 cm, where Huber is the
  /// paper's quadratic cost, and the odd wrong match only pulls linearly. Huber is convex, so
  /// unlike Cauchy it still closes loops whose residuals start far above the scale.
  /// "none" is the paper's plain weighted least squares.
  RobustLoss robustLoss = RobustLoss::Huber;
  double robustLossScale = 0.03;  ///< metres of ‖e‖ where the robust loss starts to bend
  int maxIterations = 15;         ///< Levenberg-Marquardt cap: keeps the worst case bounded
  double functionTolerance = 1e-6;
  int numThreads = 1;          ///< 1 keeps results bit-reproducible
  double minWeight = 0.0;      ///< matches with a smaller weight are dropped (weight 0 always is)
  double maxSolverTimeMs = 0;  ///< 0 = no time cap (a cap makes results timing-dependent)
  ResidualForm residualForm = ResidualForm::Landmarks;
  int irlsMaxRounds = 8;  ///< edge form with a robust loss: cap on reweighting rounds
  /// Landmark form: where the robust loss bends, in standard deviations of an observation.
  double landmarkLossScale = 2.5;
  /// Landmark form: precision of the features' pixels and depths. Not an [optimizer] key: the
  /// pipeline takes it from [features] (the same model weighs them in tracking).
  DepthNoiseModel noise;

  /// Its INI keys (section [optimizer]), listed once for loading and saving.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("rings", o.rings);
    k("robust_loss", o.robustLoss);
    k("robust_loss_scale", o.robustLossScale);
    k("max_iterations", o.maxIterations);
    k("function_tolerance", o.functionTolerance);
    k("num_threads", o.numThreads);
    k("min_weight", o.minWeight);
    k("max_solver_time_ms", o.maxSolverTimeMs);
    k("residual_form", o.residualForm);
    k("irls_max_rounds", o.irlsMaxRounds);
    k("landmark_loss_scale", o.landmarkLossScale);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
  /// Throws std::invalid_argument naming the section when a value is out of range.
  void validate(const std::string& section = "optimizer") const;
};

/// Stateless apart from its options; optimize() may run in its own thread while others read
/// poses and add keyframes/edges: it snapshots the graph, solves without holding any lock and
/// writes the free poses back with a single setPoses() call.
class LocalOptimizer {
 public:
  explicit LocalOptimizer(const LocalOptimizerOptions& options = {});

  /// Optimises the keyframes within rings 0..R-1 of root, holding ring R fixed (the root is
  /// fixed instead when ring R is empty). Vertices beyond ring R are never read or written.
  LocalOptimizationReport optimize(KeyframeGraph& graph, KeyframeId root) const;
  /// Global pass over every edge; the smallest id of each connected component is held fixed.
  LocalOptimizationReport optimizeAll(KeyframeGraph& graph) const;

  const LocalOptimizerOptions& options() const { return options_; }

 private:
  LocalOptimizerOptions options_;
};

}  // namespace slamdunk
