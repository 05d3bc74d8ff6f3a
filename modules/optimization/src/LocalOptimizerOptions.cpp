#include <slamdunk/core/IniOptions.h>
#include <slamdunk/optimization/LocalOptimizer.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace slamdunk {

void LocalOptimizerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                               const std::string& section) {
  loadIniKeys(*this, cfg, section);
  validate(section);
}

void LocalOptimizerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

void LocalOptimizerOptions::validate(const std::string& section) const {
  const SectionChecks require(section);
  require(rings >= 1, "rings must be >= 1");
  require(robustLoss == RobustLoss::None || (robustLossScale > 0 && std::isfinite(robustLossScale)),
          "robust_loss_scale must be > 0");
  require(maxIterations >= 1, "max_iterations must be >= 1");
  require(functionTolerance >= 0, "function_tolerance must be >= 0");
  require(numThreads >= 1, "num_threads must be >= 1");
  require(minWeight >= 0, "min_weight must be >= 0");
  require(irlsMaxRounds >= 1, "irls_max_rounds must be >= 1");
  require(landmarkLossScale > 0 && std::isfinite(landmarkLossScale),
          "landmark_loss_scale must be > 0");
  require(maxSolverTimeMs >= 0, "max_solver_time_ms must be >= 0 (0 = no cap)");
}

}  // namespace slamdunk
