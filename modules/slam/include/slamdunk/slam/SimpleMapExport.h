#pragma once
// The keyframe map as an mrpt::maps::CSimpleMap (".simplemap"): one (pose, sensory frame) pair
// per keyframe, so MRPT's own tools (observations2map, RawLogViewer, ...) can build point maps,
// OctoMaps or grids from SlamDunk's keyframes.
//
// Frames: MRPT expects robot/sensor poses in its sensor convention (x forward, y left, z up).
// The SLAM graph's world is the first camera's OPTICAL frame (y down); the exported world is the
// first camera's MRPT sensor frame, i.e. T_W_sensor = S · T_w_optical · S⁻¹ with
// S = opticalInSensor(). The first keyframe is therefore at the identity, and the map is z-up.
//
// Each observation is a CObservation3DRangeScan rebuilt from the keyframe images: colour (BGR,
// or grey) as the intensity image; depth as 16-bit with rangeUnits = 1e-4 m, i.e. rounded to the
// nearest 0.1 mm (error <= 0.05 mm); depths of 6.5535 m or more, and invalid ones, become 0
// ("no data"). Depth and colour are registered, so both use the keyframe's intrinsics (with
// its distortion) and relativePoseIntensityWRTDepth says the two cameras coincide. sensorPose is
// the identity: the pose in the simple map is the camera's own pose.
// MRPT's point maps (and so observations2map) insert a 3D range scan from its points3D fields
// only, never from the depth image: the export therefore also unprojects the depth into
// points3D (MRPT's own unprojectInto, one point per DxD pixel block) unless asked not to.

#include <slamdunk/core/Pose.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <string>

namespace slamdunk {

/// Metres per unit of the exported 16-bit depth.
constexpr double kSimpleMapDepthUnits = 1e-4;

/// T_W_sensor in the MRPT-convention world (first camera's sensor frame) for a pose of the
/// optical frame in the graph's world (first camera's optical frame).
Pose toMrptSensorWorld(const Pose& T_world_optical);
/// Inverse of toMrptSensorWorld().
Pose fromMrptSensorWorld(const Pose& T_W_sensor);

/// Rebuilds an observation from a keyframe that has images (throws std::invalid_argument if not).
/// points3DDecimation D > 0 also fills points3D (one point per DxD block); 0 leaves it empty.
mrpt::obs::CObservation3DRangeScan::Ptr keyframeToObservation(const Keyframe& keyframe,
                                                              int points3DDecimation = 4);

/// The simple map of the graph, keyframes in increasing id order. With keyframesWithoutImages,
/// keyframes that kept no images are included with an empty sensory frame (pose only);
/// otherwise they are left out.
mrpt::maps::CSimpleMap buildSimpleMap(const KeyframeGraph& graph,
                                      bool keyframesWithoutImages = false,
                                      int points3DDecimation = 4);

/// Writes the keyframes that have images as a gz-compressed .simplemap, atomically. Throws
/// std::runtime_error when no keyframe has images (run with tracker keep_keyframe_images = true)
/// or the file cannot be written.
void exportSimpleMap(const KeyframeGraph& graph, const std::string& path,
                     int points3DDecimation = 4);

}  // namespace slamdunk
