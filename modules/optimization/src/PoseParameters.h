#pragma once
// Ceres parameter blocks for keyframe poses: per vertex a unit quaternion (Eigen x,y,z,w order,
// on EigenQuaternionManifold) and a translation, world ← keyframe optical frame.

#include <slamdunk/graph/KeyframeGraph.h>

#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <array>
#include <map>
#include <set>

namespace slamdunk {

/// A pose as Ceres parameters: quaternion (x, y, z, w), then translation.
std::array<double, 7> poseValues(const Pose& pose);
Pose poseFromValues(const std::array<double, 7>& values);

class PoseParameters {
 public:
  PoseParameters(const std::map<KeyframeId, Pose>& poses, const std::set<KeyframeId>& fixed);

  /// Overwrites the values of the given (free) vertices.
  void setFree(const std::map<KeyframeId, Pose>& poses);
  /// Adds every block to the problem: fixed vertices constant, free quaternions on the manifold.
  void addTo(ceres::Problem& problem);
  double* quaternion(KeyframeId id) { return values_.at(id).data(); }
  double* translation(KeyframeId id) { return values_.at(id).data() + 4; }
  /// Current values of the free vertices.
  std::map<KeyframeId, Pose> freePoses() const;

 private:
  ceres::EigenQuaternionManifold manifold_;             // not owned by the problem: outlives it
  std::map<KeyframeId, std::array<double, 7>> values_;  // std::map: stable addresses
  std::set<KeyframeId> fixed_;
};

}  // namespace slamdunk
