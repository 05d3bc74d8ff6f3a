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

namespace {
template <class Self, class Keys>
void forEachKey(Self& o, Keys& k) {
  k("rings", o.rings);
  k.choice("robust_loss", o.robustLoss, robustLossFromString);
  k("robust_loss_scale", o.robustLossScale);
  k("max_iterations", o.maxIterations);
  k("function_tolerance", o.functionTolerance);
  k("num_threads", o.numThreads);
  k("min_weight", o.minWeight);
  k("max_solver_time_ms", o.maxSolverTimeMs);
  k.choice("residual_form", o.residualForm, residualFormFromString);
  k("irls_max_rounds", o.irlsMaxRounds);
  k("landmark_loss_scale", o.landmarkLossScale);
}
}  // namespace

void LocalOptimizerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                               const std::string& section) {
  IniSectionReader r(cfg, section);
  forEachKey(*this, r);
  r.rejectUnknownKeys();
  validate(section);
}

void LocalOptimizerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                             const std::string& section) const {
  IniSectionWriter w(cfg, section);
  forEachKey(*this, w);
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
