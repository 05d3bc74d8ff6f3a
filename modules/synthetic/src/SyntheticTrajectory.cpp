#include <slamdunk/synthetic/SyntheticTrajectory.h>

#include <slamdunk/core/Pose.h>
#include <slamdunk/synthetic/FloorPlan.h>
#include <slamdunk/synthetic/RoundedLoop.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace slamdunk {

namespace {

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

/// Minimum-jerk blend 0 -> 1 over u in [0, 1] (zero speed and acceleration at both ends): the
/// profile of a deliberate hand movement (Flash & Hogan 1985). Peak speed 1.875 / duration.
double minimumJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

/// "rotations": standing near the room centre, the hand turns the camera in quick sweeps about
/// each axis (yaw, pitch, roll, then combined), each a minimum-jerk move whose peak angular speed
/// reaches 80-90 deg/s, with short holds between them; it ends where it began. t in seconds.
class RotationSweeps {
 public:
  static constexpr double kDuration = 11.0;

  Pose operator()(double t) const {
    double yaw = 20, pitch = 12, roll = 0;  // start: facing the +z wall and its boxes
    double start = 0.3;
    for (const Move& m : moves()) {
      const double e = minimumJerk((t - start) / m.duration);
      yaw += m.yaw * e;
      pitch += m.pitch * e;
      roll += m.roll * e;
      start += m.duration + m.hold;
    }
    // The hand drifts a few cm meanwhile.
    const double a = 2 * M_PI * t / kDuration;
    const Eigen::Vector3d position(0.05 * std::sin(a), 0.02 * std::sin(2 * a),
                                   -0.3 + 0.04 * (1 - std::cos(a)));
    return cameraPose(position, yaw, pitch, roll);
  }

 private:
  struct Move {
    double yaw, pitch, roll;  ///< degrees turned
    double duration, hold;    ///< seconds
  };
  /// Peak speed of a move: 1.875 x angle / duration. Every move is undone later, so the
  /// sequence ends at its first pose and revisits each view.
  static const std::vector<Move>& moves() {
    static const std::vector<Move> m = {
        {-60, 0, 0, 1.3, 0.3},     // yaw right, 87 deg/s
        {0, 20, 0, 0.45, 0.2},     // pitch down, 83 deg/s
        {0, 0, 35, 0.75, 0.2},     // roll, 88 deg/s
        {0, -20, -35, 0.85, 0.3},  // back level, 89 deg/s
        {110, 0, 0, 2.4, 0.3},     // yaw left across the wall, 86 deg/s
        {0, -15, 25, 0.65, 0.2},   // pitch up and roll, 84 deg/s
        {-50, 15, -25, 1.3, 0.3},  // back to the start, 84 deg/s
    };
    return m;
  }
};

/// "shake": a slow sideways sweep (like "sweep") with a shaking hand on top: a few mm to 1.5 cm
/// at 3-7 Hz and 1-2 degrees at 3-8 Hz (peak speeds about 0.3 m/s and 50 deg/s). t in seconds.
Pose shakePose(double t, double duration) {
  const double s = std::clamp(t / duration, 0.0, 1.0);
  const double e = (1 - std::cos(M_PI * s)) / 2;
  const Eigen::Vector3d base(-0.25 + 0.5 * e, 0.0, 0.1 + 0.1 * std::sin(M_PI * s));
  auto wobble = [t](double a1, double f1, double a2, double f2, double a3, double f3, double p) {
    return a1 * std::sin(2 * M_PI * f1 * t + p) + a2 * std::sin(2 * M_PI * f2 * t + 2 * p) +
           a3 * std::sin(2 * M_PI * f3 * t + 3 * p);
  };
  const Eigen::Vector3d shake(wobble(0.006, 3.1, 0.004, 5.3, 0.002, 6.9, 0.0),
                              wobble(0.005, 3.7, 0.003, 4.9, 0.002, 7.1, 1.0),
                              wobble(0.004, 2.9, 0.003, 5.9, 0.001, 6.3, 2.0));
  const double yaw = 15 - 30 * e + wobble(1.2, 3.3, 0.6, 6.1, 0.3, 7.7, 0.5);
  const double pitch = 14 + wobble(1.0, 2.7, 0.6, 5.7, 0.3, 8.1, 1.5);
  const double roll = wobble(1.5, 3.9, 0.7, 6.7, 0.3, 7.3, 2.5);
  return cameraPose(base + shake, yaw, pitch, roll);
}

/// "dwell": standing in one spot near the room centre for a minute, turning the camera about all
/// axes as someone looking around a room does, never walking away. The view ranges over about
/// 120 degrees of yaw, 30 of pitch and 40 of roll; slow swings (periods of 7-12 s) carry it
/// through that range, quicker ones (1.7-3.1 s) take it to about 90 deg/s, and a shaking hand
/// adds a degree and a few mm at 3-8 Hz. The first slow swing (12 s) shows the whole range; after
/// it the camera keeps returning to views it has shown, from the same place, so a map that follows
/// the space covered has next to nothing to add. t in seconds.
Pose dwellPose(double t) {
  auto wave = [t](double amplitude, double period, double phase) {
    return amplitude * std::sin(2 * M_PI * t / period + phase);
  };
  auto wobble = [&](double phase) {
    return wave(0.6, 1 / 3.3, phase) + wave(0.3, 1 / 6.1, 2 * phase) +
           wave(0.2, 1 / 7.7, 3 * phase);
  };
  const double yaw = 15 + wave(45, 12, 0) + wave(8, 1.7, 0.7) + wave(5, 3.1, 2.1) + wobble(0.5);
  const double pitch = 12 + wave(10, 9, 1.0) + wave(4, 2.3, 0.3) + wobble(1.5);
  const double roll = wave(15, 7, 2.0) + wave(5, 1.9, 1.1) + wobble(2.5);
  const Eigen::Vector3d sway(wave(0.03, 13, 0) + wave(0.004, 1 / 3.1, 0),
                             wave(0.02, 17, 1) + wave(0.003, 1 / 4.9, 1),
                             wave(0.03, 11, 2) + wave(0.003, 1 / 5.9, 2));
  return cameraPose(Eigen::Vector3d(0, 0, -0.3) + sway, yaw, pitch, roll);
}

/// "scan": scanning the room by hand for 2.5 minutes. Two laps of an oval around the room centre,
/// looking outward at the walls, then across the room; the view swings left and right and up
/// and down as a person scanning would, and every place is seen again on the second lap.
/// s in [0, 1]; every term is periodic in s, so s = 1 gives the pose at s = 0.
Pose scanPose(double s) {
  const double a = 2 * M_PI * s;
  const double phi = -M_PI / 2 + 2 * a;  // two laps: a lap is half a period of a
  // Terms of even order in a repeat on the second lap; the odd ones make it differ by a few cm
  // and degrees, as a person retracing their steps would.
  const Eigen::Vector3d position(
      1.3 * std::cos(phi) + 0.03 * std::sin(16 * a) + 0.02 * std::sin(13 * a),
      0.04 * std::sin(6 * a) + 0.01 * std::sin(23 * a),
      1.0 * std::sin(phi) + 0.03 * std::sin(12 * a) + 0.02 * std::sin(17 * a));
  const double outwardYaw = std::atan2(std::cos(phi), std::sin(phi)) / kDeg;
  // Swings of +-35 degrees (four per lap) on top of looking outward, a bit ahead.
  const double yaw = outwardYaw - 25.0 + 35.0 * std::sin(8 * a) + 5.0 * std::sin(29 * a);
  const double pitch = 12.0 + 10.0 * std::sin(6 * a + 1.0) + 2.0 * std::sin(31 * a);
  const double roll = 6.0 * std::sin(10 * a) + 2.0 * std::sin(37 * a);
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

std::vector<std::string> SyntheticTrajectory::names() {
  return {"sweep", "loop", "tour", "rotations", "shake", "scan", "dwell"};
}

bool SyntheticTrajectory::isKnown(const std::string& name) {
  const auto all = names();
  return std::find(all.begin(), all.end(), name) != all.end();
}

int SyntheticTrajectory::defaultFrames(const std::string& name) {
  // Unknown names are rejected here, so generate() checks them whatever the frame count.
  if (name == "sweep") return 150;
  if (name == "loop") return 400;
  if (name == "tour") return 3300;  // 55 m at 0.5 m/s on average
  if (name == "rotations") return static_cast<int>(RotationSweeps::kDuration * kFrameRate);
  if (name == "shake") return 300;   // 10 s
  if (name == "scan") return 4500;   // 2.5 minutes
  if (name == "dwell") return 1800;  // 1 minute
  std::string known;
  for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown synthetic trajectory '" + name + "' (known: " + known + ")");
}

std::string SyntheticTrajectory::sceneOf(const std::string& name) {
  defaultFrames(name);  // throws for an unknown name
  return name == "tour" ? "office" : "room";
}

SyntheticTrajectory::PoseAtFrame SyntheticTrajectory::shape(const std::string& name, int frames) {
  const int defaults = defaultFrames(name);  // throws for an unknown name
  const int n = frames == 0 ? defaults : frames;
  if (n < 2)
    throw std::invalid_argument("a synthetic trajectory needs at least 2 frames, not " +
                                std::to_string(n));
  // The hand-held ones are laid out in time (their speeds are the point): more frames than the
  // default make them longer, not slower. The others stretch their shape over the frames.
  const double seconds = (n - 1) / kFrameRate;
  if (name == "rotations") return [](double frame) { return RotationSweeps()(frame / kFrameRate); };
  if (name == "shake")
    return [seconds](double frame) { return shakePose(frame / kFrameRate, seconds); };
  if (name == "dwell") return [](double frame) { return dwellPose(frame / kFrameRate); };
  std::function<Pose(double)> shape = sweepPose;
  if (name == "loop") shape = loopPose;
  if (name == "tour") shape = TourShape();
  if (name == "scan") shape = scanPose;
  const bool periodic = name != "sweep";
  return [shape, n, periodic](double frame) {
    const double s = frame / (n - 1);
    return shape(periodic ? s : std::clamp(s, 0.0, 1.0));
  };
}

Trajectory SyntheticTrajectory::generate(const std::string& name, int frames, double startTime) {
  const PoseAtFrame poseAt = shape(name, frames);
  const size_t n = frames == 0 ? size_t(defaultFrames(name)) : size_t(frames);
  Trajectory traj(n, StampedPose{});
  for (size_t i = 0; i < n; ++i) {
    // Whole microseconds: the TUM file's 6 decimals then hold the stamp exactly.
    traj[i].timestamp = startTime + std::round(i * 1e6 / kFrameRate) * 1e-6;
    traj[i].pose = poseAt(double(i));
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
