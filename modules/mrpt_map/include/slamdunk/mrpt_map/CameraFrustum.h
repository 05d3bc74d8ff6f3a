#pragma once
// A camera's frustum as an mrpt::opengl object, for every view of the map: the map plug-in,
// the offscreen renderer and the live viewer draw their keyframes and camera with it.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>

#include <mrpt/img/TColor.h>
#include <mrpt/opengl/CFrustum.h>

namespace slamdunk {

struct FrustumShape {
  float nearDistance = 0.0f;  ///< metres from the camera centre to the near plane
  float farDistance = 0.1f;   ///< metres from the camera centre to the far plane
  /// Degrees. A Kinect's by default: the views that draw many keyframes do not look up each
  /// keyframe's camera.
  float horzFovDeg = 58.0f, vertFovDeg = 45.0f;
  float lineWidth = 1.0f;  ///< pixels
  mrpt::img::TColor colour{255, 255, 255};

  /// The field of view of the camera's full image.
  void setFieldOfView(const CameraIntrinsics& K);
};

/// The wire-frame frustum of a camera at T_world_optical (a pose of its optical frame, as the
/// graph keeps them), drawn in world coordinates. CFrustum itself looks along its +X axis.
mrpt::opengl::CFrustum::Ptr makeCameraFrustum(const FrustumShape& shape,
                                              const Pose& T_world_optical);

}  // namespace slamdunk
