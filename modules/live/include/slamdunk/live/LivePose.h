#pragma once
// What a robot application reads from the live pipeline after each frame: the camera's pose in
// both conventions, with the frame's time and tracking state.

#include <slamdunk/core/Pose.h>
#include <slamdunk/tracking/Tracker.h>

#include <mrpt/poses/CPose3D.h>

#include <cstddef>

namespace slamdunk::live {

struct LivePose {
  bool valid = false;     ///< false until the first frame has been processed
  size_t frameIndex = 0;  ///< 0 for the first frame processed, then 1, 2, ...
  double timestamp = 0;   ///< the frame's capture time (s, as in the observation and TUM files)
  TrackingStatus status = TrackingStatus::Lost;
  /// T_world_camera of the colour camera's optical frame (x right, y down, z forward) in the
  /// map's world (the first camera's optical frame, or the loaded map's): the trajectory file's
  /// convention. While lost: the last good pose.
  Pose optical = Pose::Identity();
  /// The same pose in MRPT's conventions: the camera's sensor frame (x forward, y left, z up)
  /// in a world that is the first camera's sensor frame (z up), as CSlamDunkMapBuilder reports.
  mrpt::poses::CPose3D sensor;
  bool newKeyframe = false;
  /// A loop correction (place recognition) moved the map since the previous pose: this pose may
  /// jump by what the correction removed, and earlier poses moved with the map.
  bool loopCorrected = false;
  /// The pose is in a component of the map not joined to the map's first keyframe (the session
  /// started where its loaded map does not reach): its own frame, placed beside the map, until
  /// place recognition joins it (a loopCorrected pose).
  bool separateComponent = false;
  /// Localization only: the map covers too little of this frame's view (the camera is leaving
  /// the mapped area; nothing is added to the map there).
  bool outsideMap = false;
  double latencyMs = 0;  ///< from the frame's grab to this pose (queueing included)
};

}  // namespace slamdunk::live
