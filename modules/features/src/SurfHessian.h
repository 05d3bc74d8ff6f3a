#pragma once
// Fast-Hessian keypoint detector of SURF (private to the features module).

#include <opencv2/core.hpp>

#include <vector>

#include "SurfIntegral.h"

namespace slamdunk::surf {

struct HessianParams {
  float threshold = 500.f;
  int nOctaves = 4;
  int nOctaveLayers = 2;
  double maxOffset = 0.5;  ///< largest accepted interpolation offset, in samples
};

/// Finds scale-space maxima of the box-filter Hessian determinant, interpolated to sub-pixel and
/// sub-scale precision. Keypoints have pt, size (filter size), response, octave and class_id
/// (Laplacian sign) set, angle = -1, and are sorted by response, strongest first.
/// mask: empty or CV_8UC1 of the image size (keypoints kept where non-zero).
/// buffers: memory for the determinant maps, grown as needed; pass the same vector again on the
/// next call to reuse it (several megabytes for a VGA image).
std::vector<cv::KeyPoint> detectFastHessian(const IntegralImage& integral,
                                            const HessianParams& params, const cv::Mat& mask,
                                            std::vector<cv::Mat>& buffers);

}  // namespace slamdunk::surf
