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

FeatureType featureTypeFromString(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), ::toupper);
  if (n == "SURF64" || n == "SURF-64" || n == "SURF") return FeatureType::SURF64;
  if (n == "SURF128" || n == "SURF-128") return FeatureType::SURF128;
  if (n == "SIFT") return FeatureType::SIFT;
  if (n == "ORB") return FeatureType::ORB;
  throw std::invalid_argument("unknown feature type '" + name +
                              "' (choose SURF64, SURF128, SIFT or ORB)");
}

std::string toString(FeatureType type) {
  switch (type) {
    case FeatureType::SURF64:
      return "SURF64";
    case FeatureType::SURF128:
      return "SURF128";
    case FeatureType::SIFT:
      return "SIFT";
    case FeatureType::ORB:
      return "ORB";
  }
  return "?";
}

namespace {
template <class Self, class Keys>
void forEachKey(Self& o, Keys& k) {
  k.choice("type", o.type, featureTypeFromString);
  k("max_features", o.maxFeatures);
  k("surf_hessian_threshold", o.surfHessianThreshold);
  k("surf_upright", o.surfUpright);
  k("surf_octaves", o.surfOctaves);
  k("orb_detect_features", o.orbDetectFeatures);
  k("orb_fast_threshold", o.orbFastThreshold);
  k("sift_detect_features", o.siftDetectFeatures);
  k("min_depth", o.minDepth);
  k("max_depth", o.maxDepth);
  k("max_depth_discontinuity", o.maxDepthDiscontinuity);
  k("depth_check_radius", o.depthCheckRadius);
  k("keypoint_pixel_sigma", o.noise.pixelSigma);
  k("keypoint_depth_sigma", o.noise.depthSigmaQuadratic);
}
}  // namespace

void FeatureOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  IniSectionReader r(cfg, section);
  forEachKey(*this, r);
  r.rejectUnknownKeys();
  if (!(noise.pixelSigma > 0 && noise.depthSigmaQuadratic > 0))
    throw std::invalid_argument("[" + section +
                                "] keypoint_pixel_sigma and keypoint_depth_sigma must be > 0");
  if (maxFeatures < 3) throw std::invalid_argument("[" + section + "] max_features must be >= 3");
  if (!(minDepth >= 0 && maxDepth > minDepth))
    throw std::invalid_argument("[" + section + "] needs 0 <= min_depth < max_depth");
}

void FeatureOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section) const {
  IniSectionWriter w(cfg, section);
  forEachKey(*this, w);
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

FeatureSet FeatureExtractor::extract(const RgbdFrame& frame) const {
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

  cv::Mat descriptors;
  detector_->compute(frame.grey(), kept, descriptors);
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

}  // namespace slamdunk
