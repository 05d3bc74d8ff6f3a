#include <slamdunk/features/CompactDescriptors.h>

#include <stdexcept>

namespace slamdunk {

cv::Mat compactDescriptors(const cv::Mat& floats) {
  if (floats.empty()) return cv::Mat(floats.rows, floats.cols, CV_8SC1);
  if (floats.type() != CV_32FC1 && floats.type() != CV_16FC1)
    throw std::invalid_argument("only float descriptors have an 8-bit form");
  cv::Mat codes;
  floats.convertTo(codes, CV_8S, kCompactDescriptorScale);  // rounds and saturates
  return codes;
}

cv::Mat matchableDescriptors(const cv::Mat& descriptors) {
  switch (descriptors.type()) {
    case CV_32FC1:
    case CV_8UC1:
      return descriptors;
    case CV_16FC1: {
      cv::Mat out;
      descriptors.convertTo(out, CV_32F);
      return out;
    }
    case CV_8SC1: {
      cv::Mat out;
      descriptors.convertTo(out, CV_32F, 1.0 / kCompactDescriptorScale);
      return out;
    }
    default:
      throw std::invalid_argument(
          "descriptors must be CV_32F, CV_8U (binary), CV_8S (8-bit codes) or CV_16F rows");
  }
}

}  // namespace slamdunk
