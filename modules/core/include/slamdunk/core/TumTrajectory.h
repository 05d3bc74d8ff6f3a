#pragma once
// TUM RGB-D benchmark trajectory files: "timestamp tx ty tz qx qy qz qw" per line, '#' comments.

#include <slamdunk/core/Pose.h>

#include <memory>
#include <string>
#include <vector>

namespace slamdunk {

struct StampedPose {
  double timestamp = 0;
  Pose pose = Pose::Identity();
};
using Trajectory = std::vector<StampedPose>;

/// Reads a TUM trajectory. Throws std::runtime_error "FILE:LINE: reason" on a missing file,
/// a line with the wrong number of fields, a non-numeric or non-finite value, a position beyond
/// +-1e9 m, or a bad quaternion.
Trajectory readTumTrajectory(const std::string& path);

/// Where the tools put the keyframes' trajectory by default: "OUT_keyframes.txt" beside "OUT.txt".
std::string keyframeTrajectoryPathFor(const std::string& trajectoryPath);

/// Writes atomically (temporary file + rename): an existing file is replaced only on success.
/// Timestamps with 6 decimals, positions and quaternions with 9 significant digits.
void writeTumTrajectory(const std::string& path, const Trajectory& traj,
                        const std::string& headerComment = {});

/// The same, one pose at a time: a writer of a long session's trajectory (a live checkpoint)
/// need not hold every pose in memory at once. Nothing replaces `path` before commit().
class TumTrajectoryWriter {
 public:
  TumTrajectoryWriter(const std::string& path, const std::string& headerComment = {});
  ~TumTrajectoryWriter();
  TumTrajectoryWriter(const TumTrajectoryWriter&) = delete;
  TumTrajectoryWriter& operator=(const TumTrajectoryWriter&) = delete;
  /// Throws std::runtime_error on an invalid (NaN or non-rigid) pose.
  void add(double timestamp, const Pose& pose);
  /// Renames the file over `path`. Throws std::runtime_error on a write error.
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slamdunk
