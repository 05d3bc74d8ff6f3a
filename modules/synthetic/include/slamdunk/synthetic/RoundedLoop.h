#pragma once
// A closed walk around a convex polygon whose corners are rounded by circular arcs: straight on
// along each side, then a steady turn, as a person walks round a ring of rooms. Gives position
// and heading at any distance along it.

#include <Eigen/Core>

#include <vector>

namespace slamdunk {

class RoundedLoop {
 public:
  struct Point {
    Eigen::Vector2d position;  ///< (x, z)
    /// Direction of travel as a camera yaw: 0 = along +z, 90 = along +x (SyntheticTrajectory).
    double headingDeg = 0;
  };

  /// `corners` (x, z) in walking order, at least 3, no turn of 180 degrees; every corner is
  /// rounded with an arc of `radius`, which must leave every side a straight part (>= 0).
  /// Distance 0 is where the walk leaves the arc of corners[0], heading for corners[1].
  /// Throws std::invalid_argument otherwise.
  RoundedLoop(const std::vector<Eigen::Vector2d>& corners, double radius);

  double length() const { return length_; }
  /// Periodic: `distance` and `distance + length()` give the same point.
  Point at(double distance) const;

 private:
  /// A straight part (curvature 0) or an arc (curvature ±1/radius, + turns right), walked from
  /// `start` with heading `startHeading` (radians, yaw convention).
  struct Piece {
    Eigen::Vector2d start;
    double startHeading = 0, curvature = 0, length = 0, startDistance = 0;
  };
  std::vector<Piece> pieces_;
  double length_ = 0;
};

}  // namespace slamdunk
