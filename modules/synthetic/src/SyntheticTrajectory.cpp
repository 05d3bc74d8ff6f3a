#include <slamdunk/synthetic/SyntheticTrajectory.h>

#include <slamdunk/synthetic/FloorPlan.h>
#include <slamdunk/synthetic/RoundedLoop.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace slamdunk {

namespace {

constexpr double kDeg = M_PI / 180.0;

/// Optical-frame pose of a nearly level camera in the gravity-aligned world (y down):
/// yaw about the vertical axis (0 = looking along +z, 90 deg = along +x), then pitch (positive
/// looks down), then roll about the optical axis.
Pose cameraPose(const Eigen::Vector3d& position, double yawDeg, double pitchDownDeg,
                double rollDeg) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(yawDeg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(-pitchDownDeg * kDeg, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(rollDeg * kDeg, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  // Snap rounding residue (cos(pi/2) = 6e-17) to zero so the ground-truth file reads cleanly.
  T.translation() = position.unaryExpr([](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; });
  return T;
}

/// s in [0, 1] along the sweep. Eased in and out (zero speed at both ends, like a person
/// starting and stopping), facing the +z wall 2.8 m away and its boxes.
Pose sweepPose(double s) {
  const double e = (1 - std::cos(M_PI * s)) / 2;  // 0 -> 1 with zero slope at the ends
  const Eigen::Vector3d start(-0.2, 0.0, 0.2);
  const Eigen::Vector3d position =
      start + Eigen::Vector3d(0.40 * e, -0.04 * std::sin(M_PI * s), 0.15 * e);
  // Turning left while moving right keeps the same part of the room in view (an orbit).
  const double yaw = 12.0 - 30.0 * e;
  const double pitch = 14.0 + 3.0 * std::sin(2 * M_PI * s);
  const double roll = 2.0 * std::sin(3 * M_PI * s);
  return cameraPose(position, yaw, pitch, roll);
}

/// s in [0, 1] around the loop; every term is periodic in s, so s = 1 gives the pose at s = 0.
Pose loopPose(double s) {
  const double a = 2 * M_PI * s;     // angle travelled
  const double phi = -M_PI / 2 + a;  // start at (0, 0, -1), heading towards +x
  const double radius = 1.0;
  const Eigen::Vector3d position(radius * std::cos(phi), 0.03 * std::sin(3 * a),
                                 radius * std::sin(phi));
  // Outward (away from the room centre), turned 30 degrees towards the direction of motion.
  const double outwardYaw = std::atan2(std::cos(phi), std::sin(phi)) / kDeg;
  const double yaw = outwardYaw - 30.0 + 6.0 * std::sin(2 * a);
  const double pitch = 14.0 + 3.0 * std::sin(2 * a + 1.0);
  const double roll = 2.0 * std::sin(3 * a);
  return cameraPose(position, yaw, pitch, roll);
}

/// Once round the office's ring of rooms (A, B, C, D, back to A), starting in room A heading for
/// B. s in [0, 1]; every term is periodic in s, so s = 1 gives the pose at s = 0.
class TourShape {
 public:
  /// Arcs of 2 m: a steady turn through each room (about 15 deg/s at walking pace) that keeps
  /// well clear of the door jambs.
  static constexpr double kCornerRadius = 2.0;

  TourShape() : ring_(ringCorners(), kCornerRadius) {}

  Pose operator()(double s) const {
    const double a = 2 * M_PI * s;
    // Walking pace varies by +-10% around the mean (five slow surges per lap).
    const double distance = ring_.length() * (s + 0.1 * std::sin(5 * a) / (2 * M_PI * 5));
    const RoundedLoop::Point p = ring_.at(distance);
    // A hand-held camera drifts a few cm sideways of the walking line and bobs a little.
    const double heading = p.headingDeg * kDeg;
    const Eigen::Vector2d right(std::cos(heading), -std::sin(heading));
    const Eigen::Vector2d xz = p.position + 0.03 * std::sin(31 * a) * right;
    const double y = 0.01 * std::sin(60 * a);
    // Look to the right of the path, at the ring's outer walls and the boxes along them: straight
    // down a corridor the view would be a small, distant patch of wall. Swinging between 27 and
    // 43 degrees keeps every corridor wall in view at a changing angle.
    const double yaw = p.headingDeg + 35.0 + 8.0 * std::sin(7 * a);
    const double pitch = 12.0 + 3.0 * std::sin(11 * a + 1.0);
    const double roll = 2.5 * std::sin(13 * a);
    return cameraPose(Eigen::Vector3d(xz.x(), y, xz.y()), yaw, pitch, roll);
  }

 private:
  static std::vector<Eigen::Vector2d> ringCorners() {
    const auto c = OfficeLayout{}.roomCentres();
    return {c.begin(), c.end()};
  }
  RoundedLoop ring_;
};

}  // namespace

std::vector<std::string> SyntheticTrajectory::names() { return {"sweep", "loop", "tour"}; }

bool SyntheticTrajectory::isKnown(const std::string& name) {
  const auto all = names();
  return std::find(all.begin(), all.end(), name) != all.end();
}

int SyntheticTrajectory::defaultFrames(const std::string& name) {
  // Unknown names are rejected here, so generate() checks them whatever the frame count.
  if (name == "sweep") return 150;
  if (name == "loop") return 400;
  if (name == "tour") return 3300;  // 55 m at 0.5 m/s on average
  throw std::invalid_argument("unknown synthetic trajectory '" + name +
                              "' (known: sweep, loop, tour)");
}

std::string SyntheticTrajectory::sceneOf(const std::string& name) {
  defaultFrames(name);  // throws for an unknown name
  return name == "tour" ? "office" : "room";
}

Trajectory SyntheticTrajectory::generate(const std::string& name, int frames, double startTime) {
  const int defaults = defaultFrames(name);  // throws for an unknown name
  const int n = frames == 0 ? defaults : frames;
  if (n < 2)
    throw std::invalid_argument("a synthetic trajectory needs at least 2 frames, not " +
                                std::to_string(n));
  std::function<Pose(double)> shape = sweepPose;
  if (name == "loop") shape = loopPose;
  if (name == "tour") shape = TourShape();
  Trajectory traj(size_t(n), StampedPose{});
  for (int i = 0; i < n; ++i) {
    const double s = double(i) / (n - 1);
    // Whole microseconds: the TUM file's 6 decimals then hold the stamp exactly.
    traj[i].timestamp = startTime + std::round(i * 1e6 / kFrameRate) * 1e-6;
    traj[i].pose = shape(s);
  }
  return traj;
}

TrajectoryStats SyntheticTrajectory::stats(const Trajectory& traj) {
  TrajectoryStats st;
  st.frames = traj.size();
  if (traj.size() < 2) return st;
  st.duration = traj.back().timestamp - traj.front().timestamp;
  for (size_t i = 1; i < traj.size(); ++i) {
    const double dt = traj[i].timestamp - traj[i - 1].timestamp;
    const double dist = translationDistance(traj[i - 1].pose, traj[i].pose);
    const double angle = rotationDistance(traj[i - 1].pose, traj[i].pose) / kDeg;
    st.pathLength += dist;
    st.totalRotationDeg += angle;
    if (dt > 0) {
      st.maxSpeed = std::max(st.maxSpeed, dist / dt);
      st.maxAngularSpeedDeg = std::max(st.maxAngularSpeedDeg, angle / dt);
    }
  }
  return st;
}

}  // namespace slamdunk
