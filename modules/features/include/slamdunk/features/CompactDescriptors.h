#pragma once
// Float descriptors stored compactly. A keyframe keeps its descriptors as half floats (half the
// memory; a frame's ratio-test matches against them are those against the floats), and as 8-bit
// codes once it is far from the active window (a quarter): no pool of the current place
// searches those, and place recognition, relocalization or a later visit read them back as
// floats.

#include <opencv2/core.hpp>

namespace slamdunk {

/// Code = component × this scale, rounded: the whole range of a unit vector's components, so
/// nothing is clamped. A step of 1/127 moves a descriptor by about 0.02, and 159 of a real
/// frame's 161 ratio-test matches against another stay the same (test_compact_descriptors).
constexpr double kCompactDescriptorScale = 127.0;

/// How float descriptor rows are kept, from the most exact to the most compact.
enum class DescriptorStorage { Float, HalfFloat, Codes };

/// CV_8S codes (Codes) or CV_16F rows (HalfFloat) of CV_32F or half-float descriptor rows.
/// Other kinds, or Float: std::invalid_argument.
cv::Mat compactDescriptors(const cv::Mat& floats,
                           DescriptorStorage storage = DescriptorStorage::Codes);
/// How rows of this type keep float descriptors (Float for CV_32F and for anything else).
DescriptorStorage descriptorStorage(int type);
/// Whether the rows are 8-bit codes.
inline bool compactDescriptorType(int type) { return type == CV_8SC1; }
/// The rows as matching compares them: float rows (CV_32F) and binary ones (CV_8U) as they are
/// (not copied), half floats and 8-bit codes as CV_32F. Other kinds: std::invalid_argument.
cv::Mat matchableDescriptors(const cv::Mat& descriptors);
/// One row of float descriptors (CV_32F, CV_16F or CV_8S, `cols` long) as matching compares
/// it, written to `out`: the values matchableDescriptors gives, without a matrix per row.
void matchableRow(const uchar* row, int type, int cols, float* out);

}  // namespace slamdunk
