#pragma once
// Named camera trajectories through the synthetic scenes (FloorPlan): optical-frame poses T_w_opt
// at 30 Hz. Each trajectory is laid out for one scene (sceneOf()). The world frame is gravity
// aligned (y down, floor at y = FloorPlan::floorY, 1.3 m below the origin), and the camera
// stays nearly level (a few degrees of roll, a downward pitch) like a hand-held one.

#include <slamdunk/core/TumTrajectory.h>

#include <functional>
#include <string>
#include <vector>

namespace slamdunk {

/// Speeds and extent of a trajectory, for summaries and tests.
struct TrajectoryStats {
  size_t frames = 0;
  double duration = 0;            ///< seconds, last minus first stamp
  double pathLength = 0;          ///< metres, sum of frame-to-frame translations
  double maxSpeed = 0;            ///< m/s between consecutive frames
  double maxAngularSpeedDeg = 0;  ///< deg/s between consecutive frames
  double totalRotationDeg = 0;    ///< sum of frame-to-frame rotation angles
};

class SyntheticTrajectory {
 public:
  static constexpr double kFrameRate = 30.0;
  /// First timestamp (s): a fixed, TUM-like epoch value, never 0 (MRPT's invalid timestamp).
  static constexpr double kStartTime = 1700000000.0;

  /// "sweep": a small hand-held sweep (150 frames, 5 s): about 40 cm sideways and 15 cm
  ///   forward while panning 30 degrees, eased in and out, facing the +z wall and its boxes.
  /// "loop": a closed loop (400 frames, 13.3 s) on a 1 m circle around the room centre, looking
  ///   outward and sideways at the walls, turning 360 degrees; the last pose equals the first.
  /// Hand-held ones, laid out in time (more frames make them longer, not slower):
  /// "rotations": standing near the room centre, quick minimum-jerk sweeps about each axis and
  ///   combined (peak 83-89 deg/s, hand-like acceleration), short holds; 11 s, ends where it began.
  /// "shake": a slow sideways sweep under a shaking hand (mm to 1.5 cm at 3-7 Hz, 1-2 deg at
  ///   3-8 Hz); 10 s.
  /// "scan": a 2.5-minute room scan, two laps of an oval around the centre looking outward with
  ///   +-35 deg swings (every place is seen again on the second lap); stretched like "loop".
  /// "dwell": a minute in one spot near the room centre, turning about all axes (about 120 deg
  ///   of yaw, 30 of pitch, 40 of roll; slow swings and quick turns up to ~90 deg/s) under a
  ///   shaking hand: after its first 12 s the views keep returning to what it has shown.
  /// All but "tour" in the "room" scene.
  /// "tour": once round the "office" scene's ring of four rooms and corridors (3300 frames,
  ///   110 s, 55 m): walking pace 0.45-0.55 m/s, 2 m arcs through each room, a few cm of
  ///   sway and bob, a few degrees of roll and pitch wobble. The camera looks 27-43 degrees to
  ///   the right of the path, at the outer walls and their boxes rather than down a corridor.
  ///   A closed loop: the last pose equals the first, and the lap ends where it began.
  static std::vector<std::string> names();
  static bool isKnown(const std::string& name);
  /// Frames used when the caller asks for 0.
  static int defaultFrames(const std::string& name);
  /// The scene (FloorPlan::named) the trajectory is laid out in: the camera keeps clear of its
  /// walls and boxes there, and nowhere else. Throws std::invalid_argument for an unknown name.
  static std::string sceneOf(const std::string& name);

  /// Samples the whole shape of trajectory `name` with `frames` poses (0 = default count) at
  /// kFrameRate: fewer frames = a faster camera over the same path. Throws
  /// std::invalid_argument for an unknown name or fewer than 2 frames.
  static Trajectory generate(const std::string& name, int frames = 0,
                             double startTime = kStartTime);

  /// Pose T_w_opt at a fractional frame index (frame i is generate()'s i-th pose): the camera
  /// between frames, for motion blur, rolling shutter and sensor time offsets. Same arguments
  /// and errors as generate().
  using PoseAtFrame = std::function<Pose(double frame)>;
  static PoseAtFrame shape(const std::string& name, int frames = 0);

  static TrajectoryStats stats(const Trajectory& trajectory);
};

}  // namespace slamdunk
