#include "SurfDescriptor.h"

#include <opencv2/core/types.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace slamdunk::surf {
namespace {

// Orientation (paper, section 4.1): samples every s within radius 6s, Gaussian sigma 2s.
constexpr int kOriRadius = 6;
constexpr float kOriSigma = 2.f;
// The sliding window of pi/3 is evaluated every 5 degrees over per-5-degree bins.
constexpr int kOriBinDeg = 5;
constexpr int kOriBins = 360 / kOriBinDeg;
constexpr int kOriWindowBins = 60 / kOriBinDeg;

// Descriptor (paper, section 4.2): 20s window, 4x4 cells of 5x5 samples, Gaussian sigma 3.3s.
constexpr int kSamples = 20;
constexpr int kCellSamples = 5;
constexpr int kCells = kSamples / kCellSamples;
constexpr float kDescSigma = 3.3f;

struct OrientationSample {
  int i, j;  // offset in units of s
  float weight;
};

/// The disc of sample offsets and their Gaussian weights; they do not depend on s because both
/// the spacing and sigma scale with it.
const std::vector<OrientationSample>& orientationSamples() {
  static const std::vector<OrientationSample> samples = [] {
    std::vector<OrientationSample> out;
    for (int j = -kOriRadius; j <= kOriRadius; ++j)
      for (int i = -kOriRadius; i <= kOriRadius; ++i)
        if (i * i + j * j < kOriRadius * kOriRadius) {
          const float r2 = static_cast<float>(i * i + j * j);
          out.push_back({i, j, std::exp(-r2 / (2.f * kOriSigma * kOriSigma))});
        }
    return out;
  }();
  return samples;
}

/// Gaussian weight of descriptor sample (k, m), k along the keypoint's x axis, m along its y.
const std::array<float, kSamples * kSamples>& descriptorWeights() {
  static const std::array<float, kSamples* kSamples> weights = [] {
    std::array<float, kSamples * kSamples> w{};
    const float c = 0.5f * (kSamples - 1);
    for (int m = 0; m < kSamples; ++m)
      for (int k = 0; k < kSamples; ++k) {
        const float r2 = (k - c) * (k - c) + (m - c) * (m - c);
        w[m * kSamples + k] = std::exp(-r2 / (2.f * kDescSigma * kDescSigma));
      }
    return w;
  }();
  return weights;
}

/// atan2(y, x) in degrees, [0, 360]; error below 0.001 degree (Abramowitz & Stegun 4.4.49), far
/// finer than the 5-degree bins. Inline because it runs for every orientation sample.
inline float atan2Degrees(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float t = std::min(ax, ay) / std::max(std::max(ax, ay), 1e-30f);  // in [0, 1]
  const float t2 = t * t;
  float r = t * (0.9998660f +
                 t2 * (-0.3302995f + t2 * (0.1801410f + t2 * (-0.0851330f + t2 * 0.0208351f))));
  if (ay > ax) r = static_cast<float>(CV_PI / 2) - r;
  if (x < 0.f) r = static_cast<float>(CV_PI) - r;
  if (y < 0.f) r = static_cast<float>(2 * CV_PI) - r;
  return r * static_cast<float>(180.0 / CV_PI);
}

/// IntegralImage::haar centres its wavelet on a pixel corner, i.e. at (cx - 0.5, cy - 0.5) in
/// pixel-centre coordinates: adding 0.5 before rounding keeps the wavelet centred on p.
inline int cornerIndex(float p) { return cvRound(p + 0.5f); }

inline void accumulate(float du, float dv, bool extended, float* cell) {
  if (!extended) {
    cell[0] += du;
    cell[1] += dv;
    cell[2] += std::abs(du);
    cell[3] += std::abs(dv);
    return;
  }
  // Extended: the sums of one axis are split by the sign of the other axis' response.
  float* xs = dv >= 0.f ? cell : cell + 2;
  xs[0] += du;
  xs[1] += std::abs(du);
  float* ys = du >= 0.f ? cell + 4 : cell + 6;
  ys[0] += dv;
  ys[1] += std::abs(dv);
}

void normalise(float* v, int n) {
  double sq = 0;
  for (int i = 0; i < n; ++i) sq += static_cast<double>(v[i]) * v[i];
  if (sq <= 0) return;
  const float inv = static_cast<float>(1.0 / std::sqrt(sq));
  for (int i = 0; i < n; ++i) v[i] *= inv;
}

/// Whether every wavelet of half side `half` centred within (reachX, reachY) of p (plus the
/// rounding of cornerIndex) lies inside the image, so that haar() would clamp none.
bool windowInside(const IntegralImage& integral, const cv::Point2f& p, float reachX, float reachY,
                  int half) {
  const float margin = 2.f;  // cornerIndex's half-pixel shift and rounding
  return p.x - reachX - margin >= half && p.x + reachX + margin <= integral.cols() - half &&
         p.y - reachY - margin >= half && p.y + reachY + margin <= integral.rows() - half;
}

}  // namespace

float dominantOrientation(const IntegralImage& integral, const cv::KeyPoint& kp) {
  const float s = scaleOfSize(kp.size);
  const int half = std::max(1, cvRound(2.f * s));  // wavelet side 4s
  if (!integral.fits(half)) return 0.f;
  // The samples lie on an axis-aligned grid: round and clamp its columns and rows once.
  constexpr int kSide = 2 * kOriRadius + 1;
  std::array<int, kSide> cols;
  std::array<const uint32_t*, kSide> top, mid, bot;
  for (int i = 0; i < kSide; ++i) {
    cols[i] = integral.clampCol(cornerIndex(kp.pt.x + (i - kOriRadius) * s), half);
    const int cy = integral.clampRow(cornerIndex(kp.pt.y + (i - kOriRadius) * s), half);
    top[i] = integral.row(cy - half);
    mid[i] = integral.row(cy);
    bot[i] = integral.row(cy + half);
  }
  std::array<float, kOriBins> binX{}, binY{};
  for (const OrientationSample& sample : orientationSamples()) {
    const int r = sample.j + kOriRadius;
    float dx, dy;
    IntegralImage::haarInside(top[r], mid[r], bot[r], cols[sample.i + kOriRadius], half, dx, dy);
    if (dx == 0.f && dy == 0.f) continue;
    dx *= sample.weight;
    dy *= sample.weight;
    const int bin = std::min(static_cast<int>(atan2Degrees(dy, dx) / kOriBinDeg), kOriBins - 1);
    binX[bin] += dx;
    binY[bin] += dy;
  }
  // Window [first, first + kOriWindowBins) slides round the circle; keep the longest sum vector.
  float sumX = 0.f, sumY = 0.f;
  for (int b = 0; b < kOriWindowBins; ++b) {
    sumX += binX[b];
    sumY += binY[b];
  }
  float bestX = 0.f, bestY = 0.f, bestNorm = -1.f;
  for (int first = 0; first < kOriBins; ++first) {
    const float norm = sumX * sumX + sumY * sumY;
    if (norm > bestNorm) {
      bestNorm = norm;
      bestX = sumX;
      bestY = sumY;
    }
    const int leaving = first;
    const int entering = (first + kOriWindowBins) % kOriBins;
    sumX += binX[entering] - binX[leaving];
    sumY += binY[entering] - binY[leaving];
  }
  if (bestNorm <= 0.f) return 0.f;
  float angle = static_cast<float>(std::atan2(bestY, bestX) * (180.0 / CV_PI));
  if (angle < 0.f) angle += 360.f;
  return angle >= 360.f ? 0.f : angle;
}

void computeDescriptor(const IntegralImage& integral, const cv::KeyPoint& kp, bool extended,
                       float* out) {
  const float s = scaleOfSize(kp.size);
  const int half = std::max(1, cvRound(s));  // wavelet side 2s
  const double radians = kp.angle >= 0.f ? kp.angle * (CV_PI / 180.0) : 0.0;
  const float cosA = static_cast<float>(std::cos(radians));
  const float sinA = static_cast<float>(std::sin(radians));
  // Sample (k, m) sits at pt + (k - 9.5) s * axisU + (m - 9.5) s * axisV, where
  // axisU = (cos, sin) follows the orientation and axisV = (-sin, cos) is perpendicular to it.
  const float ux = s * cosA, uy = s * sinA;
  const float vx = -s * sinA, vy = s * cosA;
  const float c = 0.5f * (kSamples - 1);
  const float originX = kp.pt.x - c * (ux + vx);
  const float originY = kp.pt.y - c * (uy + vy);

  // 1. Haar responses of the 20 x 20 samples, in the image frame.
  std::array<float, kSamples * kSamples> dx{}, dy{};
  if (integral.fits(half) && kp.angle < 0.f) {
    // Upright: columns and rows of the grid are fixed, so round and clamp them once (same
    // result as the general path, which clamps each coordinate independently too).
    std::array<int, kSamples> cols;
    for (int k = 0; k < kSamples; ++k) {
      cols[k] = integral.clampCol(cornerIndex(originX + k * ux), half);
    }
    for (int m = 0; m < kSamples; ++m) {
      const int cy = integral.clampRow(cornerIndex(originY + m * vy), half);
      const uint32_t* top = integral.row(cy - half);
      const uint32_t* mid = integral.row(cy);
      const uint32_t* bot = integral.row(cy + half);
      for (int k = 0; k < kSamples; ++k) {
        IntegralImage::haarInside(top, mid, bot, cols[k], half, dx[m * kSamples + k],
                                  dy[m * kSamples + k]);
      }
    }
  } else if (integral.fits(half) && windowInside(integral, kp.pt, c * (std::abs(ux) + std::abs(vx)),
                                                 c * (std::abs(uy) + std::abs(vy)), half)) {
    // Turned, every wavelet inside the image: haar() without its clamping (no-ops here).
    const std::ptrdiff_t below = half * integral.stride();
    for (int m = 0; m < kSamples; ++m) {
      const float rowX = originX + m * vx;
      const float rowY = originY + m * vy;
      for (int k = 0; k < kSamples; ++k) {
        const uint32_t* mid = integral.row(cornerIndex(rowY + k * uy));
        IntegralImage::haarInside(mid - below, mid, mid + below, cornerIndex(rowX + k * ux), half,
                                  dx[m * kSamples + k], dy[m * kSamples + k]);
      }
    }
  } else {
    for (int m = 0; m < kSamples; ++m) {
      const float rowX = originX + m * vx;
      const float rowY = originY + m * vy;
      for (int k = 0; k < kSamples; ++k) {
        integral.haar(cornerIndex(rowX + k * ux), cornerIndex(rowY + k * uy), half,
                      dx[m * kSamples + k], dy[m * kSamples + k]);
      }
    }
  }

  // 2. Rotate them into the keypoint frame, weight them and sum them per cell.
  const int valuesPerCell = extended ? 8 : 4;
  const int length = kCells * kCells * valuesPerCell;
  std::fill(out, out + length, 0.f);
  const auto& weights = descriptorWeights();
  for (int m = 0; m < kSamples; ++m) {
    float* cellRow = out + (m / kCellSamples) * kCells * valuesPerCell;
    for (int k = 0; k < kSamples; ++k) {
      const int i = m * kSamples + k;
      const float du = weights[i] * (dx[i] * cosA + dy[i] * sinA);
      const float dv = weights[i] * (dy[i] * cosA - dx[i] * sinA);
      accumulate(du, dv, extended, cellRow + (k / kCellSamples) * valuesPerCell);
    }
  }
  normalise(out, length);
}

}  // namespace slamdunk::surf
