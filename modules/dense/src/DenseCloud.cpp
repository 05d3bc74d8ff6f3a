#include <slamdunk/dense/DenseCloud.h>

#include <algorithm>
#include <cmath>

namespace slamdunk {

void DenseCloud::append(const DenseCloud& other) {
  points.insert(points.end(), other.points.begin(), other.points.end());
  colours.insert(colours.end(), other.colours.begin(), other.colours.end());
}

bool DenseCloud::boundingBox(Eigen::Vector3f& min, Eigen::Vector3f& max, double lowQuantile,
                             double highQuantile) const {
  if (points.empty()) return false;
  lowQuantile = std::clamp(lowQuantile, 0.0, 1.0);
  highQuantile = std::clamp(highQuantile, lowQuantile, 1.0);
  if (lowQuantile == 0.0 && highQuantile == 1.0) {
    min = max = points.front();
    for (const auto& p : points) {
      min = min.cwiseMin(p);
      max = max.cwiseMax(p);
    }
    return true;
  }
  // Quantiles per axis (nth_element on a copy): a few stray far readings do not blow the box up.
  std::vector<float> axis(points.size());
  const auto at = [&](double q) {
    return static_cast<size_t>(std::lround(q * static_cast<double>(axis.size() - 1)));
  };
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < points.size(); ++i) axis[i] = points[i][k];
    std::nth_element(axis.begin(), axis.begin() + at(lowQuantile), axis.end());
    min[k] = axis[at(lowQuantile)];
    std::nth_element(axis.begin(), axis.begin() + at(highQuantile), axis.end());
    max[k] = axis[at(highQuantile)];
  }
  return true;
}

}  // namespace slamdunk
