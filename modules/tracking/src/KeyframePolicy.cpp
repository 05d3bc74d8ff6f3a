#include <slamdunk/tracking/KeyframePolicy.h>

#include <algorithm>

namespace slamdunk {

namespace {
std::vector<int> cellCounts(const std::vector<cv::Point2f>& pts, int cols, int rows, int width,
                            int height) {
  std::vector<int> counts(cols * rows, 0);
  for (const auto& p : pts) {
    const int c = std::clamp(static_cast<int>(p.x * cols / width), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(p.y * rows / height), 0, rows - 1);
    ++counts[r * cols + c];
  }
  return counts;
}
}  // namespace

double KeyframePolicy::overlap(const std::vector<cv::Point2f>& inlierPixels,
                               const std::vector<cv::Point2f>& allFeaturePixels, int width,
                               int height, int* eligibleCells) const {
  const int cols = std::max(1, options_.gridCols), rows = std::max(1, options_.gridRows);
  const auto inl = cellCounts(inlierPixels, cols, rows, width, height);
  const auto all = cellCounts(allFeaturePixels, cols, rows, width, height);
  int eligible = 0, covered = 0;
  for (size_t i = 0; i < inl.size(); ++i) {
    if (options_.onlyTexturedCells &&
        (all[i] <= options_.minInliersPerCell || all[i] < options_.texturedCellFeatures))
      continue;
    ++eligible;
    if (inl[i] > options_.minInliersPerCell) ++covered;
  }
  if (eligibleCells) *eligibleCells = eligible;
  return eligible == 0 ? 0.0 : static_cast<double>(covered) / eligible;
}

}  // namespace slamdunk
