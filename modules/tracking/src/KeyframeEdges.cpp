#include <slamdunk/tracking/KeyframeEdges.h>

#include <algorithm>
#include <map>

namespace slamdunk {

KeyframeEdges::KeyframeEdges(const TrackerOptions& options, const DepthNoiseModel& noise,
                             KeyframeGraph& graph, const DenseDepthTerm& dense)
    : options_(options), noise_(noise), graph_(graph), dense_(dense) {}

PointMatch weighedPointMatch(const FeatureSet& other, uint32_t otherIndex, const FeatureSet& fresh,
                             uint32_t freshIndex, double ratio,
                             const Eigen::Matrix3d& R_other_fresh, const DepthNoiseModel& noise,
                             EdgeInformation information, double keypointScaleSigma) {
  // Normalised so that a match of two points 1 m away keeps about the paper's weight.
  const double unitVariance = 2 * noise.variance(1.0);
  // As measured, not as refined: each edge keeps the measurements the optimization weighs.
  const Eigen::Vector3d& pOther = other.points[otherIndex];
  const Eigen::Vector3d& pNew = fresh.points[freshIndex];
  const double scaleVarOther =
      noise.keypointScaleVariance(pOther.z(), other.keypoints[otherIndex].size, keypointScaleSigma);
  const double scaleVarNew =
      noise.keypointScaleVariance(pNew.z(), fresh.keypoints[freshIndex].size, keypointScaleSigma);
  PointMatch pm{pOther, pNew, 1.0 - ratio};  // paper Sec. 4.3: w = 1 - θ'
  pm.featureI = otherIndex;
  pm.featureJ = freshIndex;
  switch (information) {
    case EdgeInformation::Paper:
      break;
    case EdgeInformation::Isotropic:
      pm.weight *= unitVariance / (noise.variance(pOther.z()) + noise.variance(pNew.z()) +
                                   scaleVarOther + scaleVarNew);
      break;
    case EdgeInformation::Anisotropic: {
      const Eigen::Matrix3d& R = R_other_fresh;
      auto across = [](const Eigen::Vector3d& p) {
        const Eigen::Vector3d ray = p.normalized();
        return Eigen::Matrix3d(Eigen::Matrix3d::Identity() - ray * ray.transpose());
      };
      const Eigen::Matrix3d covOther = noise.covariance(pOther) + scaleVarOther * across(pOther);
      const Eigen::Matrix3d covNew = noise.covariance(pNew) + scaleVarNew * across(pNew);
      pm.information = unitVariance * (covOther + R * covNew * R.transpose()).inverse();
      break;
    }
  }
  return pm;
}

void KeyframeEdges::linkMatches(KeyframeId id, const FeatureSet& features,
                                const Registration& registration) {
  const Eigen::Matrix3d R_new = graph_.pose(id).linear();
  std::map<KeyframeId, KeyframePtr> others;
  std::map<KeyframeId, Eigen::Matrix3d> relativeRotation;  // other <- new
  std::map<KeyframeId, std::vector<PointMatch>> perKeyframe;
  for (const PoolMatch& m : registration.inlierMatches) {
    const PoolFeature& f = registration.pool->feature(m.pool);
    auto other = others.find(f.keyframe);
    if (other == others.end())
      other = others.emplace(f.keyframe, graph_.keyframe(f.keyframe)).first;
    if (!other->second) continue;  // culled since the pool was built
    auto R = relativeRotation.find(f.keyframe);
    if (R == relativeRotation.end())
      R = relativeRotation.emplace(f.keyframe, graph_.pose(f.keyframe).linear().transpose() * R_new)
              .first;
    perKeyframe[f.keyframe].push_back(
        weighedPointMatch(other->second->features, f.index, features, m.query, m.ratio, R->second,
                          noise_, options_.edgeInformation, options_.keypointScaleSigma));
  }
  for (const auto& [other, pm] : perKeyframe)
    if (static_cast<int>(pm.size()) >= options_.edgeMinMatches) graph_.addMatches(other, id, pm);
}

void KeyframeEdges::linkDepth(KeyframeId id, const Pose& pose) {
  const DenseDepthTerm::Last& last = dense_.last;
  if (!last.term || !graph_.contains(last.reference)) return;
  const auto all = depthCorrespondences(pose, *last.term);
  if (all.empty()) return;
  // Evenly thinned to bound the map's size; the weight keeps the total information.
  const size_t keep = std::min<size_t>(all.size(), options_.depthEdgeMaxMatches);
  const double scale = static_cast<double>(all.size()) / keep;
  const double unitVariance = 2 * noise_.variance(1.0);
  std::vector<PointMatch> matches;
  matches.reserve(keep);
  for (size_t k = 0; k < keep; ++k) {
    const DepthCorrespondence& c = all[k * all.size() / keep];
    // Point-to-plane: e's component along the normal only (a small isotropic part keeps Ω
    // invertible for the per-match residual form).
    PointMatch m{c.referencePoint, c.framePoint,
                 options_.depthEdgeWeight * scale * unitVariance / (c.sigma * c.sigma)};
    m.information = c.normal * c.normal.transpose() + 1e-6 * Eigen::Matrix3d::Identity();
    matches.push_back(m);
  }
  graph_.addMatches(last.reference, id, matches);
}

}  // namespace slamdunk
