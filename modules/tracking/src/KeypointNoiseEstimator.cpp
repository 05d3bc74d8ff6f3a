#include <slamdunk/core/Statistics.h>
#include <slamdunk/tracking/KeypointNoiseEstimator.h>

#include <algorithm>
#include <cmath>

namespace slamdunk {

namespace {
// Medians of |x| for x ~ N(0, σ²): 0.6745 σ; of the length of a 2D N(0, σ² I): 1.1774 σ.
constexpr double kHalfNormalMedian = 0.6745;
constexpr double kRayleighMedian = 1.1774;
}  // namespace

KeypointNoiseEstimator::KeypointNoiseEstimator(const DepthNoiseModel& prior,
                                               const KeypointNoiseEstimatorOptions& o)
    : prior_(prior), current_(prior), options_(o) {}

void KeypointNoiseEstimator::addFrame(const std::vector<InlierSample>& inliers, const Pose& pose) {
  if (!options_.enabled || static_cast<int>(inliers.size()) < options_.minSamples) return;
  const Pose frameFromWorld = pose.inverse();
  const double f = prior_.focalLength;
  std::vector<double> across, along, zFrame, zMap;
  for (const InlierSample& s : inliers) {
    const double z = s.framePoint.z(), zm = s.mapDepth;
    if (!(z > 0 && zm > 0)) continue;
    const Eigen::Vector3d e = frameFromWorld * s.mapPoint - s.framePoint;
    const Eigen::Vector3d ray = s.framePoint.normalized();
    const double a = e.dot(ray);
    // Both points' lateral errors add up: pixels at their depths.
    across.push_back((e - a * ray).norm() / std::hypot(z / f, zm / f));
    along.push_back(std::abs(a));
    zFrame.push_back(z);
    zMap.push_back(zm);
  }
  if (static_cast<int>(across.size()) < options_.minSamples) return;
  const double pixelSigma = std::clamp(upperMedian(across) / kRayleighMedian,
                                       options_.minPixelSigma, options_.maxPixelSigma);
  // The depth coefficient whose predicted spread explains the median along-ray error: the
  // normalised errors' median falls as the coefficient grows, so bisect (in log scale).
  DepthNoiseModel m = prior_;
  m.pixelSigma = pixelSigma;
  auto normalisedMedian = [&](double coefficient) {
    m.depthSigmaQuadratic = coefficient;
    std::vector<double> n(along.size());
    for (size_t i = 0; i < along.size(); ++i)
      n[i] = along[i] / std::hypot(m.depthSigma(zFrame[i]), m.depthSigma(zMap[i]));
    return upperMedian(std::move(n));
  };
  double lo = std::log(options_.minDepthSigma), hi = std::log(options_.maxDepthSigma);
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    (normalisedMedian(std::exp(mid)) > kHalfNormalMedian ? lo : hi) = mid;
  }
  const double depthSigma = std::exp(0.5 * (lo + hi));

  pixelSigmas_.push_back(pixelSigma);
  depthSigmas_.push_back(depthSigma);
  if (static_cast<int>(pixelSigmas_.size()) > options_.window) {
    pixelSigmas_.pop_front();
    depthSigmas_.pop_front();
  }
  ++measured_;
  if (static_cast<int>(measured_) < options_.minFrames) return;
  current_.pixelSigma = upperMedian({pixelSigmas_.begin(), pixelSigmas_.end()});
  current_.depthSigmaQuadratic = upperMedian({depthSigmas_.begin(), depthSigmas_.end()});
}

}  // namespace slamdunk
