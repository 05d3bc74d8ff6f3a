#pragma once
// Float descriptors stored as 8-bit codes. A keyframe far from the active window keeps its
// descriptors so (a quarter of the memory): no pool of the current place searches them, and
// place recognition, relocalization or a later visit read them back as floats.

#include <opencv2/core.hpp>

namespace slamdunk {

/// Code = component × this scale, rounded: the whole range of a unit vector's components, so
/// nothing is clamped. A step of 1/127 moves a descriptor by about 0.02, and 159 of a real
/// frame's 161 ratio-test matches against another stay the same (test_compact_descriptors).
constexpr double kCompactDescriptorScale = 127.0;

/// CV_8S codes of CV_32F (or half-float) descriptor rows.
cv::Mat compactDescriptors(const cv::Mat& floats);
/// Whether the rows are such codes.
inline bool compactDescriptorType(int type) { return type == CV_8SC1; }
/// The rows as matching compares them: float rows (CV_32F) and binary ones (CV_8U) as they are
/// (not copied), half floats and 8-bit codes as CV_32F. Other kinds: std::invalid_argument.
cv::Mat matchableDescriptors(const cv::Mat& descriptors);

}  // namespace slamdunk
