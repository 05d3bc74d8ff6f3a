#include <slamdunk/core/IniOptions.h>
#include <slamdunk/optimization/LocalOptimizer.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace slamdunk {

RobustLoss robustLossFromString(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), ::tolower);
  if (n == "none") return RobustLoss::None;
  if (n == "huber") return RobustLoss::Huber;
  if (n == "cauchy") return RobustLoss::Cauchy;
  throw std::invalid_argument("unknown robust loss '" + name + "' (choose none, huber or cauchy)");
}

std::string toString(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::None:
      return "none";
    case RobustLoss::Huber:
      return "huber";
    case RobustLoss::Cauchy:
      return "cauchy";
  }
  return "?";
}

ResidualForm residualFormFromString(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), ::tolower);
  if (n == "edge") return ResidualForm::Edge;
  if (n == "match") return ResidualForm::Match;
  if (n == "landmarks") return ResidualForm::Landmarks;
  throw std::invalid_argument("unknown residual form '" + name +
                              "' (choose edge, match or landmarks)");
}

std::string toString(ResidualForm form) {
  switch (form) {
    case ResidualForm::Edge:
      return "edge";
    case ResidualForm::Match:
      return "match";
    case ResidualForm::Landmarks:
      return "landmarks";
  }
  return "?";
}

void LocalOptimizerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                               const std::string& section) {
  IniSectionReader r(cfg, section);
  rings = r.readInt("rings", rings);
  robustLoss = robustLossFromString(r.readString("robust_loss", toString(robustLoss)));
  robustLossScale = r.readDouble("robust_loss_scale", robustLossScale);
  maxIterations = r.readInt("max_iterations", maxIterations);
  functionTolerance = r.readDouble("function_tolerance", functionTolerance);
  numThreads = r.readInt("num_threads", numThreads);
  minWeight = r.readDouble("min_weight", minWeight);
  maxSolverTimeMs = r.readDouble("max_solver_time_ms", maxSolverTimeMs);
  residualForm = residualFormFromString(r.readString("residual_form", toString(residualForm)));
  irlsMaxRounds = r.readInt("irls_max_rounds", irlsMaxRounds);
  landmarkLossScale = r.readDouble("landmark_loss_scale", landmarkLossScale);
  r.rejectUnknownKeys();
  validate(section);
}

void LocalOptimizerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section) const {
  cfg.write(section, "rings", rings);
  cfg.write(section, "robust_loss", toString(robustLoss));
  cfg.write(section, "robust_loss_scale", robustLossScale);
  cfg.write(section, "max_iterations", maxIterations);
  cfg.write(section, "function_tolerance", functionTolerance);
  cfg.write(section, "num_threads", numThreads);
  cfg.write(section, "min_weight", minWeight);
  cfg.write(section, "max_solver_time_ms", maxSolverTimeMs);
  cfg.write(section, "residual_form", toString(residualForm));
  cfg.write(section, "irls_max_rounds", irlsMaxRounds);
  cfg.write(section, "landmark_loss_scale", landmarkLossScale);
}

void LocalOptimizerOptions::validate(const std::string& section) const {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument("[" + section + "] " + what);
  };
  if (rings < 1) fail("rings must be >= 1");
  if (robustLoss != RobustLoss::None && !(robustLossScale > 0 && std::isfinite(robustLossScale)))
    fail("robust_loss_scale must be > 0");
  if (maxIterations < 1) fail("max_iterations must be >= 1");
  if (!(functionTolerance >= 0)) fail("function_tolerance must be >= 0");
  if (numThreads < 1) fail("num_threads must be >= 1");
  if (!(minWeight >= 0)) fail("min_weight must be >= 0");
  if (irlsMaxRounds < 1) fail("irls_max_rounds must be >= 1");
  if (!(landmarkLossScale > 0 && std::isfinite(landmarkLossScale)))
    fail("landmark_loss_scale must be > 0");
  if (!(maxSolverTimeMs >= 0)) fail("max_solver_time_ms must be >= 0 (0 = no cap)");
}

}  // namespace slamdunk
