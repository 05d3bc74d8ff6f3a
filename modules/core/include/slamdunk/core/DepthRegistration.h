#pragma once
// Depth registration: a depth image taken by a camera beside the colour camera (an RGB-D sensor
// whose depth is not registered, such as a raw Kinect v1) resampled into the colour camera's
// pixel grid, so that the depth at a colour pixel belongs to the surface seen at that pixel.

#include <slamdunk/core/CameraIntrinsics.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace slamdunk {

/// Each valid depth pixel (value > 0; CV_16UC1 or CV_32FC1, metresPerUnit metres) is lifted to 3D
/// with the depth camera's intrinsics, moved into the colour camera's optical frame by
/// depthToColour and (translation in metres) projected with the colour camera's intrinsics
/// (distortion included). It fills the colour pixels its footprint covers; where several surfaces
/// land on one pixel the nearest wins, as it occludes the others. Returns an image of the colour
/// camera's size and the input's type, holding depth along the colour camera's axis in the input's
/// units; 0 where nothing landed.
cv::Mat registerDepthToColour(const cv::Mat& depth, const CameraIntrinsics& depthCamera,
                              const CameraIntrinsics& colourCamera,
                              const Eigen::Isometry3d& depthToColour, double metresPerUnit = 1.0);

}  // namespace slamdunk
