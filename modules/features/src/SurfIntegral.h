#pragma once
// Integral image and Haar-wavelet helpers shared by the SURF detector and descriptor (private).

#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdint>

namespace slamdunk::surf {

/// Summed-area table of an 8-bit image: row(y)[x] = sum of pixels [0, x) x [0, y).
/// Sums are kept modulo 2^32 (uint32_t, defined wrap-around): the sum over any box of fewer than
/// 2^23 pixels comes out exact from the corner differences (as an int32), whatever the image size.
class IntegralImage {
 public:
  /// storage: where the table is kept; reusing it across calls avoids faulting in fresh pages.
  IntegralImage(const cv::Mat& gray8, cv::Mat& storage);

  int rows() const { return rows_; }  ///< image rows (the table has one more)
  int cols() const { return cols_; }  ///< image columns (the table has one more)
  std::ptrdiff_t stride() const { return stride_; }
  const uint32_t* row(int y) const { return data_ + y * stride_; }

  /// Haar wavelet responses of side 2h whose centre is the pixel corner (cx, cy):
  /// x = right half - left half, y = bottom half - top half. The centre is clamped so the
  /// wavelet stays inside the image (edge replication in effect, no fake border edges);
  /// both are 0 if the image is smaller than the wavelet.
  void haar(int cx, int cy, int h, float& dx, float& dy) const {
    if (!fits(h)) {
      dx = dy = 0.f;
      return;
    }
    cy = clampRow(cy, h);
    haarInside(row(cy - h), row(cy), row(cy + h), clampCol(cx, h), h, dx, dy);
  }

  bool fits(int h) const { return 2 * h <= cols_ && 2 * h <= rows_; }
  int clampCol(int cx, int h) const { return std::clamp(cx, h, cols_ - h); }
  int clampRow(int cy, int h) const { return std::clamp(cy, h, rows_ - h); }

  /// haar() for a wavelet known to be inside, given the table rows cy - h, cy and cy + h.
  static void haarInside(const uint32_t* top, const uint32_t* mid, const uint32_t* bot, int cx,
                         int h, float& dx, float& dy) {
    const uint32_t left = bot[cx - h] - top[cx - h];
    const uint32_t centreCol = bot[cx] - top[cx];
    const uint32_t right = bot[cx + h] - top[cx + h];
    dx = static_cast<float>(static_cast<int32_t>(right - 2u * centreCol + left));
    const uint32_t topHalf = mid[cx + h] - mid[cx - h] - (top[cx + h] - top[cx - h]);
    const uint32_t all = bot[cx + h] - bot[cx - h] - (top[cx + h] - top[cx - h]);
    dy = static_cast<float>(static_cast<int32_t>(all - 2u * topHalf));
  }

 private:
  cv::Mat table_;  // (rows+1) x (cols+1), CV_32S storage read as uint32_t
  const uint32_t* data_ = nullptr;
  std::ptrdiff_t stride_ = 0;
  int rows_ = 0;
  int cols_ = 0;
};

/// Paper: scale s = 1.2 / 9 * filter size (KeyPoint::size holds the filter size).
inline float scaleOfSize(float filterSize) { return filterSize * (1.2f / 9.f); }

}  // namespace slamdunk::surf
