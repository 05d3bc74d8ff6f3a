#include "SurfIntegral.h"

namespace slamdunk::surf {

// Written by hand rather than with cv::integral so that sums wrap modulo 2^32 with defined
// behaviour (unsigned arithmetic) instead of overflowing a signed int on very large images.
IntegralImage::IntegralImage(const cv::Mat& gray8, cv::Mat& storage)
    : rows_(gray8.rows), cols_(gray8.cols) {
  CV_Assert(gray8.type() == CV_8UC1);
  storage.create(rows_ + 1, cols_ + 1, CV_32S);
  table_ = storage;
  data_ = table_.ptr<uint32_t>(0);
  stride_ = static_cast<std::ptrdiff_t>(table_.step1());
  uint32_t* first = table_.ptr<uint32_t>(0);
  std::fill(first, first + cols_ + 1, 0u);
  for (int y = 0; y < rows_; ++y) {
    const uint8_t* src = gray8.ptr<uint8_t>(y);
    const uint32_t* above = table_.ptr<uint32_t>(y);
    uint32_t* out = table_.ptr<uint32_t>(y + 1);
    out[0] = 0;
    uint32_t rowSum = 0;
    for (int x = 0; x < cols_; ++x) {
      rowSum += src[x];
      out[x + 1] = above[x + 1] + rowSum;
    }
  }
}

}  // namespace slamdunk::surf
