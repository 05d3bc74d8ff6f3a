#include <slamdunk/optimization/ComponentMotion.h>

#include "PointMatchResidual.h"
#include "PoseParameters.h"

#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <array>

namespace slamdunk {

std::optional<Pose> fitRigidMotion(const std::vector<AnchoredMatches>& loops, const Pose& initial) {
  size_t count = 0;
  for (const AnchoredMatches& loop : loops) count += loop.matches.size();
  if (count < 3) return {};
  // The moving keyframe's points are taken in the world frame before the move: then the
  // residual is PointMatchResidual's, with the motion itself as the moving "pose".
  std::vector<std::array<double, 7>> fixedPoses;
  fixedPoses.reserve(loops.size());
  for (const AnchoredMatches& loop : loops) fixedPoses.push_back(poseValues(loop.fixedPose));
  std::array<double, 7> motion = poseValues(initial);

  ceres::Problem::Options problemOptions;
  problemOptions.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problemOptions);
  ceres::EigenQuaternionManifold manifold;
  problem.AddParameterBlock(motion.data(), 4, &manifold);
  problem.AddParameterBlock(motion.data() + 4, 3);
  for (size_t k = 0; k < loops.size(); ++k) {
    double* fixed = fixedPoses[k].data();
    problem.AddParameterBlock(fixed, 4);
    problem.AddParameterBlock(fixed + 4, 3);
    problem.SetParameterBlockConstant(fixed);
    problem.SetParameterBlockConstant(fixed + 4);
    for (const PointMatch& m : loops[k].matches)
      problem.AddResidualBlock(PointMatchResidual::create(m.pointI, loops[k].movingPose * m.pointJ,
                                                          m.weight, m.information),
                               nullptr, fixed, fixed + 4, motion.data(), motion.data() + 4);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return {};
  const Pose fitted = poseFromValues(motion);
  if (!isValidPose(fitted)) return {};
  return fitted;
}

}  // namespace slamdunk
