#include <slamdunk/tracking/KeyframeEdges.h>

#include <algorithm>
#include <map>

namespace slamdunk {

KeyframeEdges::KeyframeEdges(const TrackerOptions& options, const DepthNoiseModel& noise,
                             KeyframeGraph& graph, const DenseDepthTerm& dense)
    : options_(options), noise_(noise), graph_(graph), dense_(dense) {}

void KeyframeEdges::linkMatches(KeyframeId id, const FeatureSet& features,
                                const Registration& registration) {
  // Normalised so that a match of two points 1 m away keeps about the paper's weight.
  const double unitVariance = 2 * noise_.variance(1.0);
  const double scaleSigma = options_.keypointScaleSigma;
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
    // As measured, not as refined: each edge keeps the measurements the optimization weighs.
    const Eigen::Vector3d& pOther = other->second->features.points[f.index];
    const Eigen::Vector3d& pNew = features.points[m.query];
    const double scaleVarOther = noise_.keypointScaleVariance(
        pOther.z(), other->second->features.keypoints[f.index].size, scaleSigma);
    const double scaleVarNew =
        noise_.keypointScaleVariance(pNew.z(), features.keypoints[m.query].size, scaleSigma);
    PointMatch pm{pOther, pNew, 1.0 - m.ratio};  // paper Sec. 4.3: w = 1 - θ'
    pm.featureI = f.index;
    pm.featureJ = m.query;
    switch (options_.edgeInformation) {
      case EdgeInformation::Paper:
        break;
      case EdgeInformation::Isotropic:
        pm.weight *= unitVariance / (noise_.variance(pOther.z()) + noise_.variance(pNew.z()) +
                                     scaleVarOther + scaleVarNew);
        break;
      case EdgeInformation::Anisotropic: {
        auto it = relativeRotation.find(f.keyframe);
        if (it == relativeRotation.end())
          it = relativeRotation
                   .emplace(f.keyframe, graph_.pose(f.keyframe).linear().transpose() * R_new)
                   .first;
        const Eigen::Matrix3d& R = it->second;
        auto across = [](const Eigen::Vector3d& p) {
          const Eigen::Vector3d ray = p.normalized();
          return Eigen::Matrix3d(Eigen::Matrix3d::Identity() - ray * ray.transpose());
        };
        const Eigen::Matrix3d covOther = noise_.covariance(pOther) + scaleVarOther * across(pOther);
        const Eigen::Matrix3d covNew = noise_.covariance(pNew) + scaleVarNew * across(pNew);
        pm.information = unitVariance * (covOther + R * covNew * R.transpose()).inverse();
        break;
      }
    }
    perKeyframe[f.keyframe].push_back(pm);
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
