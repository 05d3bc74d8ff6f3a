#include "PoseParameters.h"

namespace slamdunk {

std::array<double, 7> poseValues(const Pose& pose) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(pose.linear()).normalized();
  const Eigen::Vector3d t = pose.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

Pose poseFromValues(const std::array<double, 7>& x) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Quaterniond(x[3], x[0], x[1], x[2]).normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x[4], x[5], x[6]);
  return pose;
}

PoseParameters::PoseParameters(const std::map<KeyframeId, Pose>& poses,
                               const std::set<KeyframeId>& fixed)
    : fixed_(fixed) {
  for (const auto& [id, pose] : poses) values_[id] = poseValues(pose);
}

void PoseParameters::setFree(const std::map<KeyframeId, Pose>& poses) {
  for (const auto& [id, pose] : poses)
    if (!fixed_.count(id)) values_.at(id) = poseValues(pose);
}

void PoseParameters::addTo(ceres::Problem& problem) {
  for (auto& [id, x] : values_) {
    problem.AddParameterBlock(x.data(), 4);
    problem.AddParameterBlock(x.data() + 4, 3);
    if (fixed_.count(id)) {
      problem.SetParameterBlockConstant(x.data());
      problem.SetParameterBlockConstant(x.data() + 4);
    } else {
      problem.SetManifold(x.data(), &manifold_);
    }
  }
}

std::map<KeyframeId, Pose> PoseParameters::freePoses() const {
  std::map<KeyframeId, Pose> out;
  for (const auto& [id, x] : values_) {
    if (fixed_.count(id)) continue;
    out.emplace(id, poseFromValues(x));
  }
  return out;
}

}  // namespace slamdunk
