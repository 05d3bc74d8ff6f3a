#include <slamdunk/core/DepthBackProjection.h>

namespace slamdunk {

std::optional<std::array<uint8_t, 3>> rgbAt(const cv::Mat& image, int u, int v) {
  if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) return std::nullopt;
  if (image.type() == CV_8UC3) {
    const cv::Vec3b& bgr = image.at<cv::Vec3b>(v, u);
    return std::array<uint8_t, 3>{bgr[2], bgr[1], bgr[0]};
  }
  if (image.type() == CV_8UC1) {
    const uint8_t g = image.at<uint8_t>(v, u);
    return std::array<uint8_t, 3>{g, g, g};
  }
  return std::nullopt;
}

}  // namespace slamdunk
