#pragma once
// Keyframes with random features, shared by the feature-pool and local-map tests.

#include <slamdunk/graph/Keyframe.h>

#include <opencv2/core.hpp>

#include <memory>

namespace slamdunk::test {

/// n random unit SURF-64-like descriptors, reproducible for a seed.
inline cv::Mat randomDescriptors(int n, unsigned seed) {
  cv::Mat d(n, 64, CV_32F);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::NORMAL, 0, 1);
  for (int i = 0; i < n; ++i) cv::normalize(d.row(i), d.row(i));
  return d;
}

/// A keyframe whose features have these descriptors, at points about 2 m in front of it
/// (a 10 cm-wide grid, well inside any window frustum).
inline KeyframePtr makeKeyframe(KeyframeId id, const cv::Mat& descriptors) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = id;
  kf->features.descriptors = descriptors.clone();
  for (int i = 0; i < descriptors.rows; ++i) {
    kf->features.keypoints.emplace_back(cv::Point2f(320, 240), 10.f);
    kf->features.points.emplace_back(0.001 * (i % 100), 0.001 * (i / 100), 2.0);
  }
  return kf;
}

}  // namespace slamdunk::test
