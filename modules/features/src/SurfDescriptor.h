#pragma once
// SURF orientation assignment and descriptor (private to the features module).

#include <opencv2/core.hpp>

#include "SurfIntegral.h"

namespace slamdunk::surf {

/// Dominant orientation in degrees [0, 360) (image coordinates, y down): Haar responses of side
/// 4s on a radius-6s disc, Gaussian weighted (sigma 2s), summed in a sliding 60-degree window.
float dominantOrientation(const IntegralImage& integral, const cv::KeyPoint& kp);

/// Writes the 64 (or 128 if extended) values of the descriptor of kp to out, unit L2 norm.
/// The 20s window is rotated by kp.angle unless it is negative (upright).
void computeDescriptor(const IntegralImage& integral, const cv::KeyPoint& kp, bool extended,
                       float* out);

}  // namespace slamdunk::surf
