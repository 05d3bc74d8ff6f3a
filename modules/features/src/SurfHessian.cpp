#include "SurfHessian.h"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace slamdunk::surf {
namespace {

// Paper, section 4.1: the first octave uses filters 9, 15, 21, 27 (step 6); every further octave
// doubles the size step and the sampling step, and starts at the second size of the previous one
// (15, 27, 39, 51; 27, 51, 75, 99; ...), i.e. size = 3 + step * (layer + 1).
constexpr int kFirstSizeStep = 6;
// Weight of Dxy in det(H) ~ Dxx Dyy - (w Dxy)^2, w = 0.9, compensating the box approximation.
constexpr float kDxyWeightSq = 0.81f;
// Grid rows per parallel task: small enough to balance 2+ threads, big enough to amortise.
constexpr int kRowsPerTask = 24;

/// A box [x0, x1) x [y0, y1) relative to the filter centre, stored as the four integral-image
/// offsets, so that sum = p[d] - p[b] - p[c] + p[a] with p pointing at the centre.
struct Box {
  std::ptrdiff_t a, b, c, d;
};

Box makeBox(int x0, int y0, int x1, int y1, std::ptrdiff_t stride) {
  return {y0 * stride + x0, y0 * stride + x1, y1 * stride + x0, y1 * stride + x1};
}

/// The box filters approximating the second-order Gaussian derivatives for one filter size.
/// Lobe l = size / 3 (odd). Dyy: a (2l-1) x 3l box minus 3 x its middle third; Dxx transposed;
/// Dxy: four l x l squares around a 1-pixel cross, +1 on the diagonal, -1 off it.
struct HessianKernel {
  Box yyAll, yyMid, xxAll, xxMid, xyTL, xyTR, xyBL, xyBR;
  // Each lobe is averaged (sum / lobe area), as in OpenCV's SURF, so thresholds carry over.
  float invLobeArea = 0.f;    // Dxx, Dyy lobes: l x (2l - 1)
  float invSquareArea = 0.f;  // Dxy lobes: l x l

  HessianKernel(int size, std::ptrdiff_t stride) {
    const int l = size / 3;
    const int half = size / 2;  // (3l - 1) / 2: half extent of the long side
    const int midHalf = l / 2;  // (l - 1) / 2: half extent of the middle lobe
    yyAll = makeBox(-(l - 1), -half, l, half + 1, stride);
    yyMid = makeBox(-(l - 1), -midHalf, l, midHalf + 1, stride);
    xxAll = makeBox(-half, -(l - 1), half + 1, l, stride);
    xxMid = makeBox(-midHalf, -(l - 1), midHalf + 1, l, stride);
    xyTL = makeBox(-l, -l, 0, 0, stride);
    xyTR = makeBox(1, -l, l + 1, 0, stride);
    xyBL = makeBox(-l, 1, 0, l + 1, stride);
    xyBR = makeBox(1, 1, l + 1, l + 1, stride);
    invLobeArea = 1.f / static_cast<float>(l * (2 * l - 1));
    invSquareArea = 1.f / static_cast<float>(l * l);
  }
};

inline int32_t boxSum(const uint32_t* p, const Box& b) {
  return static_cast<int32_t>(p[b.d] - p[b.b] - p[b.c] + p[b.a]);
}

struct Hessian {
  float dxx, dyy, dxy;
};

inline Hessian hessianAt(const uint32_t* p, const HessianKernel& k) {
  const int32_t yy = boxSum(p, k.yyAll) - 3 * boxSum(p, k.yyMid);
  const int32_t xx = boxSum(p, k.xxAll) - 3 * boxSum(p, k.xxMid);
  const int32_t xy = boxSum(p, k.xyTL) + boxSum(p, k.xyBR) - boxSum(p, k.xyTR) - boxSum(p, k.xyBL);
  return {xx * k.invLobeArea, yy * k.invLobeArea, xy * k.invSquareArea};
}

/// Pointers to the four integral-image corners of a box for the sample at centre.
struct BoxCorners {
  const uint32_t *a, *b, *c, *d;
  BoxCorners(const uint32_t* centre, const Box& box)
      : a(centre + box.a), b(centre + box.b), c(centre + box.c), d(centre + box.d) {}
  int32_t sum(std::ptrdiff_t o) const { return static_cast<int32_t>(d[o] - b[o] - c[o] + a[o]); }
};

// The row functions below fix the sampling step at compile time (kStep > 0): with kStep == 1
// the loads are contiguous and the compiler vectorises them. Dxx, Dyy and Dxy are computed in
// separate passes so that each loop's pointers fit in registers.

/// out[i] = scale * (sum(all) - 3 sum(mid)): Dxx or Dyy along one grid row.
template <int kStep>
void secondDerivativeRow(const uint32_t* centre, int n, std::ptrdiff_t runtimeStep, const Box& all,
                         const Box& mid, float scale, float* __restrict out) {
  const std::ptrdiff_t step = kStep > 0 ? kStep : runtimeStep;
  const BoxCorners outer(centre, all), inner(centre, mid);
  for (int i = 0; i < n; ++i) {
    const std::ptrdiff_t o = i * step;
    out[i] = static_cast<float>(outer.sum(o) - 3 * inner.sum(o)) * scale;
  }
}

/// det[i] = dxx[i] * det[i] - (0.9 Dxy)^2, where det holds Dyy on entry.
template <int kStep>
void determinantRow(const uint32_t* centre, int n, std::ptrdiff_t runtimeStep,
                    const HessianKernel& k, float* __restrict dxx, float* __restrict det) {
  const std::ptrdiff_t step = kStep > 0 ? kStep : runtimeStep;
  secondDerivativeRow<kStep>(centre, n, step, k.yyAll, k.yyMid, k.invLobeArea, det);
  secondDerivativeRow<kStep>(centre, n, step, k.xxAll, k.xxMid, k.invLobeArea, dxx);
  const BoxCorners tl(centre, k.xyTL), tr(centre, k.xyTR), bl(centre, k.xyBL), br(centre, k.xyBR);
  const float scale = k.invSquareArea;
  for (int i = 0; i < n; ++i) {
    const std::ptrdiff_t o = i * step;
    const float dxy = static_cast<float>(tl.sum(o) + br.sum(o) - tr.sum(o) - bl.sum(o)) * scale;
    det[i] = dxx[i] * det[i] - kDxyWeightSq * dxy * dxy;
  }
}

/// One filter size of the scale space: its determinant map on the octave's sampling grid.
struct Layer {
  int octave = 0;
  int size = 0;        // filter side in pixels
  int sampleStep = 1;  // grid spacing in pixels
  // Grid cells (inclusive) where the whole filter fits in the image; empty if x0 > x1.
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  cv::Mat det;  // CV_32F, grid rows x grid cols; allocated if not empty

  bool empty() const { return x0 > x1 || y0 > y1; }
};

Layer makeLayer(int octave, int layerIndex, int rows, int cols, cv::Mat& buffer) {
  Layer layer;
  layer.octave = octave;
  layer.sampleStep = 1 << octave;
  layer.size = 3 + (kFirstSizeStep << octave) * (layerIndex + 1);
  const int half = layer.size / 2;
  const int step = layer.sampleStep;
  // Pixel g * step is a valid centre if half <= g * step <= dim - 1 - half.
  layer.x0 = (half + step - 1) / step;
  layer.y0 = (half + step - 1) / step;
  layer.x1 = cols - 1 - half >= 0 ? (cols - 1 - half) / step : -1;
  layer.y1 = rows - 1 - half >= 0 ? (rows - 1 - half) / step : -1;
  // Left uninitialised outside the valid range: nothing reads there (see findMaxima).
  if (!layer.empty()) {
    buffer.create((rows + step - 1) / step, (cols + step - 1) / step, CV_32F);
    layer.det = buffer;
  }
  return layer;
}

/// Layer i of octave o has the size of layer 2i + 1 of octave o - 1 (or -1 if none), whose map
/// then already holds every other sample of it.
int finerTwin(int layerIndex, int nOctaveLayers) {
  const int twin = 2 * layerIndex + 1;
  return twin <= nOctaveLayers + 1 ? twin : -1;
}

/// dst = every other row and column of src, over dst's valid range.
void subsample(const Layer& src, Layer& dst) {
  for (int gy = dst.y0; gy <= dst.y1; ++gy) {
    const float* in = src.det.ptr<float>(2 * gy);
    float* out = dst.det.ptr<float>(gy);
    for (int gx = dst.x0; gx <= dst.x1; ++gx) out[gx] = in[2 * gx];
  }
}

void fillDeterminant(const IntegralImage& integral, Layer& layer, int gy0, int gy1) {
  const HessianKernel kernel(layer.size, integral.stride());
  const int step = layer.sampleStep;
  const int n = layer.x1 - layer.x0 + 1;
  std::vector<float> dxx(n);
  for (int gy = gy0; gy < gy1; ++gy) {
    const uint32_t* centre = integral.row(gy * step) + layer.x0 * step;
    float* out = layer.det.ptr<float>(gy) + layer.x0;
    switch (step) {
      case 1:
        determinantRow<1>(centre, n, step, kernel, dxx.data(), out);
        break;
      case 2:
        determinantRow<2>(centre, n, step, kernel, dxx.data(), out);
        break;
      default:
        determinantRow<0>(centre, n, step, kernel, dxx.data(), out);
        break;
    }
  }
}

/// A band of grid rows of one layer: the unit of parallel work.
struct RowBand {
  int layer;
  int begin, end;
};

std::vector<RowBand> splitRows(const std::vector<int>& layerIds, const std::vector<Layer>& layers) {
  std::vector<RowBand> bands;
  for (int id : layerIds) {
    const Layer& layer = layers[id];
    for (int y = layer.y0; y <= layer.y1; y += kRowsPerTask) {
      bands.push_back({id, y, std::min(y + kRowsPerTask, layer.y1 + 1)});
    }
  }
  return bands;
}

/// The 3x3x3 neighbourhood n[scale][dy][dx] of a candidate, scale 0 = smaller filter.
using Cube = float[3][3][3];

bool isStrictMaximum(const Cube& n) {
  const float v = n[1][1][1];
  for (int s = 0; s < 3; ++s)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x)
        if ((s != 1 || y != 1 || x != 1) && !(v > n[s][y][x])) return false;
  return true;
}

/// Fits a 3D quadratic to the neighbourhood (Brown & Lowe) and returns the offset of its
/// extremum in grid cells / layers, and the interpolated value. False if the fit is degenerate
/// or the extremum lies farther than maxOffset from the centre in any axis (beyond 0.5 it is
/// nearer a neighbouring sample: the fit is poor).
bool interpolateMaximum(const Cube& n, double maxOffset, cv::Vec3d& offset, double& value) {
  const double v = n[1][1][1];
  const cv::Vec3d g((n[1][1][2] - n[1][1][0]) * 0.5, (n[1][2][1] - n[1][0][1]) * 0.5,
                    (n[2][1][1] - n[0][1][1]) * 0.5);
  const double dxx = n[1][1][2] - 2 * v + n[1][1][0];
  const double dyy = n[1][2][1] - 2 * v + n[1][0][1];
  const double dss = n[2][1][1] - 2 * v + n[0][1][1];
  const double dxy = (n[1][2][2] - n[1][2][0] - n[1][0][2] + n[1][0][0]) * 0.25;
  const double dxs = (n[2][1][2] - n[2][1][0] - n[0][1][2] + n[0][1][0]) * 0.25;
  const double dys = (n[2][2][1] - n[2][0][1] - n[0][2][1] + n[0][0][1]) * 0.25;
  const cv::Matx33d h(dxx, dxy, dxs, dxy, dyy, dys, dxs, dys, dss);
  if (std::abs(cv::determinant(h)) < 1e-12) return false;
  offset = h.solve(-g, cv::DECOMP_LU);
  if (!(std::abs(offset[0]) <= maxOffset && std::abs(offset[1]) <= maxOffset &&
        std::abs(offset[2]) <= maxOffset))
    return false;
  value = v + 0.5 * g.dot(offset);
  return true;
}

struct FindContext {
  const IntegralImage* integral;
  const std::vector<Layer>* layers;
  const cv::Mat* mask;
  float threshold;
  double maxOffset;
};

/// Full test of a pre-selected sample (gx, gy) of layer mid: strict maximum of its 3x3x3
/// neighbourhood (rows[scale][dy] are the rows gy - 1..gy + 1 of the three layers), interpolated
/// and inside the mask. Appends the keypoint to out if it passes.
void testCandidate(const FindContext& ctx, const float* const (&rows)[3][3], int gx, int gy,
                   const HessianKernel& kernel, const Layer& mid, const Layer& above,
                   std::vector<cv::KeyPoint>& out) {
  Cube cube;
  for (int s = 0; s < 3; ++s)
    for (int dy = 0; dy < 3; ++dy)
      for (int dx = 0; dx < 3; ++dx) cube[s][dy][dx] = rows[s][dy][gx + dx - 1];
  if (!isStrictMaximum(cube)) return;
  cv::Vec3d offset;
  double value = 0;
  if (!interpolateMaximum(cube, ctx.maxOffset, offset, value)) return;
  const int step = mid.sampleStep;
  const float x = static_cast<float>((gx + offset[0]) * step);
  const float y = static_cast<float>((gy + offset[1]) * step);
  if (!ctx.mask->empty() && ctx.mask->at<uint8_t>(cvRound(y), cvRound(x)) == 0) return;
  const float sizeStep = static_cast<float>(above.size - mid.size);
  const float size = mid.size + static_cast<float>(offset[2]) * sizeStep;
  const Hessian h = hessianAt(ctx.integral->row(gy * step) + gx * step, kernel);
  const float trace = h.dxx + h.dyy;
  const int laplacianSign = (trace > 0) - (trace < 0);
  out.emplace_back(x, y, size, -1.f, static_cast<float>(value), mid.octave, laplacianSign);
}

/// Scans rows [band.begin, band.end) of middle layer band.layer (with layers band.layer -+ 1
/// below/above it in the same octave) and appends the interpolated maxima to out.
void findMaxima(const FindContext& ctx, const RowBand& band, std::vector<cv::KeyPoint>& out) {
  const std::vector<Layer>& layers = *ctx.layers;
  const Layer& below = layers[band.layer - 1];
  const Layer& mid = layers[band.layer];
  const Layer& above = layers[band.layer + 1];
  const HessianKernel kernel(mid.size, ctx.integral->stride());
  // The largest filter fits in the smallest range; one more cell for the 3x3 neighbourhood.
  const int x0 = above.x0 + 1;
  const int x1 = above.x1 - 1;
  const int width = std::max(0, x1 - x0 + 1);
  // Padded to whole 8-byte words so the scan below can read them at once.
  std::vector<uint8_t> passes((width + 7) / 8 * 8, 0);
  const float threshold = ctx.threshold;
  for (int gy = band.begin; gy < band.end; ++gy) {
    const float* rows[3][3];
    const Layer* triple[3] = {&below, &mid, &above};
    for (int s = 0; s < 3; ++s)
      for (int dy = 0; dy < 3; ++dy) rows[s][dy] = triple[s]->det.ptr<float>(gy + dy - 1);
    // Pre-selection (above threshold and both horizontal neighbours) without branches, so the
    // compiler vectorises it; about 1% of the samples pass on real images.
    const float* c = rows[1][1] + x0;
    for (int i = 0; i < width; ++i) {
      passes[i] = (c[i] > threshold) & (c[i] > c[i - 1]) & (c[i] > c[i + 1]);
    }
    for (int word = 0; word < width; word += 8) {
      uint64_t bits;
      std::memcpy(&bits, &passes[word], sizeof bits);
      if (bits == 0) continue;
      for (int i = word; i < word + 8 && i < width; ++i) {
        if (passes[i]) testCandidate(ctx, rows, x0 + i, gy, kernel, mid, above, out);
      }
    }
  }
}

/// Strongest first; the remaining keys only make the order total, hence deterministic.
bool strongerFirst(const cv::KeyPoint& a, const cv::KeyPoint& b) {
  if (a.response != b.response) return a.response > b.response;
  if (a.size != b.size) return a.size > b.size;
  if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
  return a.pt.x < b.pt.x;
}

}  // namespace

std::vector<cv::KeyPoint> detectFastHessian(const IntegralImage& integral,
                                            const HessianParams& params, const cv::Mat& mask,
                                            std::vector<cv::Mat>& buffers) {
  const int layersPerOctave = params.nOctaveLayers + 2;
  if (buffers.size() < static_cast<size_t>(params.nOctaves * layersPerOctave)) {
    buffers.resize(params.nOctaves * layersPerOctave);
  }
  std::vector<Layer> layers;
  std::vector<int> computed, middleLayers;
  std::vector<std::pair<int, int>> copies;  // (source, destination), in octave order
  for (int o = 0; o < params.nOctaves; ++o) {
    const int first = static_cast<int>(layers.size());
    for (int i = 0; i < layersPerOctave; ++i) {
      const int id = first + i;
      layers.push_back(makeLayer(o, i, integral.rows(), integral.cols(), buffers[id]));
      if (layers.back().empty()) continue;
      const int twin = o > 0 ? finerTwin(i, params.nOctaveLayers) : -1;
      if (twin >= 0) {
        copies.emplace_back(first - layersPerOctave + twin, id);
      } else {
        computed.push_back(id);
      }
    }
    for (int i = 1; i <= params.nOctaveLayers; ++i) {
      if (!layers[first + i + 1].empty()) middleLayers.push_back(first + i);
    }
  }

  // 1. Determinant maps: the new filter sizes at once, in bands of rows, then the sizes shared
  // with the previous octave by subsampling its maps (about a third less filtering).
  const std::vector<RowBand> detBands = splitRows(computed, layers);
  cv::parallel_for_(cv::Range(0, static_cast<int>(detBands.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      fillDeterminant(integral, layers[detBands[i].layer], detBands[i].begin, detBands[i].end);
    }
  });
  for (const auto& [src, dst] : copies) subsample(layers[src], layers[dst]);

  // 2. Maxima in the middle layers. Candidate rows are limited by the layer above (largest
  // filter) and by one cell for the neighbourhood; each band writes its own list.
  std::vector<RowBand> findBands;
  for (int id : middleLayers) {
    const Layer& above = layers[id + 1];
    for (int y = above.y0 + 1; y <= above.y1 - 1; y += kRowsPerTask) {
      findBands.push_back({id, y, std::min(y + kRowsPerTask, above.y1)});
    }
  }
  std::vector<std::vector<cv::KeyPoint>> found(findBands.size());
  const FindContext ctx{&integral, &layers, &mask, params.threshold, params.maxOffset};
  cv::parallel_for_(cv::Range(0, static_cast<int>(findBands.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) findMaxima(ctx, findBands[i], found[i]);
  });

  std::vector<cv::KeyPoint> keypoints;
  for (const auto& f : found) keypoints.insert(keypoints.end(), f.begin(), f.end());
  std::sort(keypoints.begin(), keypoints.end(), strongerFirst);
  return keypoints;
}

}  // namespace slamdunk::surf
