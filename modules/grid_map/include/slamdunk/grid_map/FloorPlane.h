#pragma once
// Where the floor is in a map made by a hand-held or robot camera, found from the map itself:
// the lowest horizontal plane below the cameras with enough of the keyframes' depth on it.

#include <slamdunk/core/Pose.h>

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace slamdunk {

struct FloorFrame {
  /// z up along the floor's normal, origin on the floor below the first camera, x that camera's
  /// viewing direction along the floor (the robot convention: x forward, y left, z up).
  Pose T_world_floor = Pose::Identity();
  size_t supportingPoints = 0;  ///< sampled points within 3 cm of the floor plane
};

/// The floor frame from points in the map's world and the cameras that saw them (the first one
/// sets the frame's origin and heading). "Up" is first taken against the cameras' mean image
/// down direction (they are held roughly upright; pitched down at a table, the mean tilts by
/// tens of degrees, so planes within 35 degrees of it are considered); a seeded RANSAC finds the
/// best supported plane that leans no more than that and lies below the cameras (a table top or
/// the floor), and the floor is the lowest plane parallel to it that holds a fair share of the
/// points. Nothing when no such plane exists (the cameras never looked at the floor).
/// Deterministic: the same inputs give the same frame.
std::optional<FloorFrame> findFloor(const std::vector<Eigen::Vector3f>& worldPoints,
                                    const std::vector<Pose>& T_world_cameras);

}  // namespace slamdunk
