#include <slamdunk/core/IniOptions.h>
#include <slamdunk/features/FeatureExtractor.h>
#ifdef SLAMDUNK_HAVE_SURF
#include <slamdunk/features/Surf.h>
#endif

#include <opencv2/features2d.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace slamdunk {

void FeatureOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  loadIniKeys(*this, cfg, section);
  const SectionChecks require(section);
  require(noise.pixelSigma > 0 && noise.depthSigmaQuadratic > 0,
          "keypoint_pixel_sigma and keypoint_depth_sigma must be > 0");
  require(maxFeatures >= 3, "max_features must be >= 3");
  require(minDepth >= 0 && maxDepth > minDepth, "needs 0 <= min_depth < max_depth");
}

void FeatureOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

namespace {

/// True when every valid depth around (u, v) is within `fraction` of z.
bool depthIsSmooth(const cv::Mat& depth, double u, double v, float z, int radius, double fraction) {
  const int cu = static_cast<int>(std::lround(u)), cv_ = static_cast<int>(std::lround(v));
  const float tol = static_cast<float>(fraction) * z;
  for (int r = std::max(0, cv_ - radius); r <= std::min(depth.rows - 1, cv_ + radius); ++r) {
    const float* row = depth.ptr<float>(r);
    for (int c = std::max(0, cu - radius); c <= std::min(depth.cols - 1, cu + radius); ++c)
      if (row[c] <= 0 || std::abs(row[c] - z) > tol) return false;
  }
  return true;
}

cv::Ptr<cv::Feature2D> makeDetector(const FeatureOptions& o) {
  switch (o.type) {
    case FeatureType::SURF64:
    case FeatureType::SURF128: {
#ifdef SLAMDUNK_HAVE_SURF
      Surf::Params p;
      p.hessianThreshold = o.surfHessianThreshold;
      p.nOctaves = o.surfOctaves;
      p.extended = o.type == FeatureType::SURF128;
      p.upright = o.surfUpright;
      return Surf::create(p);
#else
      throw std::invalid_argument(
          "this build has no SURF (configured with SLAMDUNK_WITH_SURF=OFF)");
#endif
    }
    case FeatureType::SIFT:
      return cv::SIFT::create(o.siftDetectFeatures);
    case FeatureType::ORB:
      return cv::ORB::create(o.orbDetectFeatures, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                             o.orbFastThreshold);
  }
  throw std::logic_error("unhandled feature type");
}
}  // namespace

FeatureExtractor::FeatureExtractor(const FeatureOptions& options)
    : options_(options), detector_(makeDetector(options)) {}

FeatureExtractor::~FeatureExtractor() = default;

int FeatureExtractor::descriptorNorm() const {
  return options_.type == FeatureType::ORB ? cv::NORM_HAMMING : cv::NORM_L2;
}

FeatureSet FeatureExtractor::extract(const RgbdFrame& frame, double turnDegrees) const {
  FeatureSet out;
  if (frame.grey().empty()) return out;
  std::vector<cv::KeyPoint> detected;
  detector_->detect(frame.grey(), detected);

  // Keep the strongest keypoints that have usable depth; sort is stable on index so equal
  // responses keep detector order and runs stay deterministic.
  std::vector<size_t> order(detected.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return detected[a].response > detected[b].response; });
  std::vector<cv::KeyPoint> kept;
  std::vector<Eigen::Vector3d> points;
  for (size_t idx : order) {
    if (static_cast<int>(kept.size()) >= options_.maxFeatures) break;
    const cv::KeyPoint& kp = detected[idx];
    const auto p = frame.backProject(kp.pt.x, kp.pt.y);
    if (!p || p->z() < options_.minDepth || p->z() > options_.maxDepth) continue;
    if (options_.depthCheckRadius > 0 &&
        !depthIsSmooth(frame.depth(), kp.pt.x, kp.pt.y, static_cast<float>(p->z()),
                       options_.depthCheckRadius, options_.maxDepthDiscontinuity))
      continue;
    kept.push_back(kp);
    points.push_back(*p);
  }
  if (kept.empty()) return out;

  const cv::Mat descriptors = describe(frame.grey(), kept, turnDegrees);
  // compute() may drop keypoints near the border and may reorder them (ORB regroups them by
  // pyramid level): re-associate the 3D points with the keypoints it returns.
  points.clear();
  points.reserve(kept.size());
  for (const auto& kp : kept) points.push_back(*frame.backProject(kp.pt.x, kp.pt.y));
  kept.shrink_to_fit();  // a keyframe keeps these for the map's lifetime
  out.keypoints = std::move(kept);
  out.descriptors = descriptors;
  out.points = std::move(points);
  return out;
}

bool FeatureExtractor::turnsDescriptors() const {
  return options_.surfUpright && options_.surfRollLimitDeg > 0 &&
         (options_.type == FeatureType::SURF64 || options_.type == FeatureType::SURF128);
}

cv::Mat FeatureExtractor::describe(const cv::Mat& grey, std::vector<cv::KeyPoint>& keypoints,
                                   double turnDegrees) const {
  cv::Mat descriptors;
#ifdef SLAMDUNK_HAVE_SURF
  if (turnDegrees != 0 && turnsDescriptors()) {
    static_cast<Surf&>(*detector_)
        .computeTurned(grey, keypoints, descriptors, static_cast<float>(turnDegrees));
    return descriptors;
  }
#endif
  detector_->compute(grey, keypoints, descriptors);
  return descriptors;
}

bool FeatureExtractor::describeTurned(const RgbdFrame& frame, FeatureSet& features,
                                      double turnDegrees) const {
  if (!turnsDescriptors() || features.keypoints.empty()) return false;
  std::vector<cv::KeyPoint> keypoints = features.keypoints;
  cv::Mat descriptors = describe(frame.grey(), keypoints, turnDegrees);
  if (keypoints.size() != features.keypoints.size())
    throw std::logic_error("describeTurned(): a described keypoint left the image");
  features.keypoints = std::move(keypoints);
  features.descriptors = descriptors;
  return true;
}

bool FeatureExtractor::describedWith(const FeatureSet& features, double turnDegrees) const {
  if (!turnsDescriptors() || features.keypoints.empty()) return turnDegrees == 0;
  // Upright windows carry no angle (-1), turned ones the turn as SURF stores it.
  const float angle = features.keypoints.front().angle;
  if (turnDegrees == 0) return angle < 0;
#ifdef SLAMDUNK_HAVE_SURF
  return angle == Surf::turnedAngle(static_cast<float>(turnDegrees));
#else
  return false;
#endif
}

}  // namespace slamdunk
