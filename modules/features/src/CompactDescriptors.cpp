#include <slamdunk/features/CompactDescriptors.h>

#include <opencv2/core/hal/hal.hpp>

#include <cstring>
#include <stdexcept>

namespace slamdunk {

cv::Mat compactDescriptors(const cv::Mat& floats, DescriptorStorage storage) {
  if (floats.type() != CV_32FC1 && floats.type() != CV_16FC1)
    throw std::invalid_argument("only float descriptors have a compact form");
  cv::Mat out;
  switch (storage) {
    case DescriptorStorage::Codes:
      if (floats.empty()) return cv::Mat(floats.rows, floats.cols, CV_8SC1);
      floats.convertTo(out, CV_8S, kCompactDescriptorScale);  // rounds and saturates
      return out;
    case DescriptorStorage::HalfFloat:
      if (floats.empty()) return cv::Mat(floats.rows, floats.cols, CV_16FC1);
      floats.convertTo(out, CV_16F);  // rounds to nearest
      return out;
    case DescriptorStorage::Float:
      break;
  }
  throw std::invalid_argument("floats are not a compact form");
}

void matchableRow(const uchar* row, int type, int cols, float* out) {
  switch (type) {
    case CV_32FC1:
      std::memcpy(out, row, sizeof(float) * cols);
      return;
    case CV_16FC1:
      cv::hal::cvt16f32f(reinterpret_cast<const cv::float16_t*>(row), out, cols);
      return;
    case CV_8SC1: {
      const cv::Mat codes(1, cols, CV_8SC1, const_cast<uchar*>(row));
      cv::Mat floats(1, cols, CV_32FC1, out);
      codes.convertTo(floats, CV_32F, 1.0 / kCompactDescriptorScale);  // writes into `out`
      return;
    }
    default:
      throw std::invalid_argument("only float descriptor rows have a matchable float form");
  }
}

DescriptorStorage descriptorStorage(int type) {
  switch (type) {
    case CV_16FC1:
      return DescriptorStorage::HalfFloat;
    case CV_8SC1:
      return DescriptorStorage::Codes;
    default:
      return DescriptorStorage::Float;
  }
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
