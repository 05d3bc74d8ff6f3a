#include "PoseProblem.h"

#include "PointMatchResidual.h"

#include <ceres/loss_function.h>

namespace slamdunk {

namespace {
ceres::Problem::Options problemOptions() {
  ceres::Problem::Options o;
  // Losses and the manifold are members of PoseProblem; cost functions are owned by Ceres.
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return o;
}

std::unique_ptr<ceres::LossFunction> makeRobust(const LocalOptimizerOptions& o) {
  // Ceres' scale a is on s = ‖r‖²: Huber/Cauchy bend where ‖r‖ ≈ a, so a = scale in metres.
  switch (o.robustLoss) {
    case RobustLoss::None: return nullptr;
    case RobustLoss::Huber: return std::make_unique<ceres::HuberLoss>(o.robustLossScale);
    case RobustLoss::Cauchy: return std::make_unique<ceres::CauchyLoss>(o.robustLossScale);
  }
  return nullptr;
}
}  // namespace

PoseProblem::PoseProblem(const LocalProblem& p, const LocalOptimizerOptions& options)
    : robust_(makeRobust(options)), fixed_(p.fixed), problem_(problemOptions()) {
  for (const auto& [id, pose] : p.poses) {
    Parameters& x = parameters_[id] = toParameters(pose);
    problem_.AddParameterBlock(x.data(), 4);
    problem_.AddParameterBlock(x.data() + 4, 3);
    if (fixed_.count(id)) {
      problem_.SetParameterBlockConstant(x.data());
      problem_.SetParameterBlockConstant(x.data() + 4);
    } else {
      problem_.SetManifold(x.data(), &quaternionManifold_);
    }
  }
  for (const KeyframeEdge& e : p.edges) {
    double* xi = parameters_.at(e.i).data();
    double* xj = parameters_.at(e.j).data();
    for (const PointMatch& m : e.matches) {
      problem_.AddResidualBlock(PointMatchResidual::create(m.pointI, m.pointJ, m.weight),
                                makeLoss(m.weight), xi, xi + 4,
                                xj, xj + 4);
      ++residuals_;
    }
  }
}

ceres::LossFunction* PoseProblem::makeLoss(double weight) {
  if (!robust_) return nullptr;
  return &weightedLosses_.emplace_back(robust_.get(), weight);
}

ceres::Solver::Summary PoseProblem::solve(const LocalOptimizerOptions& o) {
  ceres::Solver::Options s;
  s.minimizer_type = ceres::TRUST_REGION;
  s.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  s.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  s.max_num_iterations = o.maxIterations;
  s.function_tolerance = o.functionTolerance;
  s.num_threads = o.numThreads;
  if (o.maxSolverTimeMs > 0) s.max_solver_time_in_seconds = o.maxSolverTimeMs / 1000.0;
  s.minimizer_progress_to_stdout = false;
  s.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  std::string why;
  if (!s.IsValid(&why)) {  // e.g. a Ceres build without SuiteSparse
    summary.termination_type = ceres::FAILURE;
    summary.message = "invalid solver options: " + why;
    return summary;
  }
  ceres::Solve(s, &problem_, &summary);
  return summary;
}

std::map<KeyframeId, Pose> PoseProblem::freePoses() const {
  std::map<KeyframeId, Pose> out;
  for (const auto& [id, x] : parameters_)
    if (!fixed_.count(id)) out.emplace(id, toPose(x));
  return out;
}

PoseProblem::Parameters PoseProblem::toParameters(const Pose& pose) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(pose.linear()).normalized();
  const Eigen::Vector3d t = pose.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

Pose PoseProblem::toPose(const Parameters& x) {
  const Eigen::Quaterniond q(x[3], x[0], x[1], x[2]);  // (w, x, y, z) constructor
  Pose pose = Pose::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x[4], x[5], x[6]);
  return pose;
}

}  // namespace slamdunk
