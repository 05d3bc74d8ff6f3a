#include <slamdunk/graph/LandmarkTracks.h>

#include <map>
#include <numeric>

namespace slamdunk {

LandmarkTracks buildLandmarkTracks(const std::vector<KeyframeEdge>& edges) {
  LandmarkTracks out;
  std::map<std::pair<KeyframeId, uint32_t>, size_t> nodeOf;  // (keyframe, feature) -> node
  std::vector<LandmarkObservation> nodes;
  std::vector<size_t> parent;
  auto node = [&](KeyframeId keyframe, uint32_t feature, const Eigen::Vector3d& point) {
    const auto [it, added] = nodeOf.try_emplace({keyframe, feature}, nodes.size());
    if (added) {
      nodes.push_back({keyframe, feature, point});
      parent.push_back(parent.size());
    }
    return it->second;
  };
  auto root = [&](size_t n) {
    while (parent[n] != n) n = parent[n] = parent[parent[n]];
    return n;
  };
  for (size_t e = 0; e < edges.size(); ++e) {
    const KeyframeEdge& edge = edges[e];
    for (size_t m = 0; m < edge.matches.size(); ++m) {
      const PointMatch& match = edge.matches[m];
      if (!match.joinsFeatures()) {
        out.pointMatches.emplace_back(e, m);
        continue;
      }
      const size_t a = root(node(edge.i, match.featureI, match.pointI));
      const size_t b = root(node(edge.j, match.featureJ, match.pointJ));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root is a track's first node
    }
  }
  // Nodes in creation order: each track is gathered in the order its observations were reached.
  std::map<size_t, size_t> landmarkOfRoot;
  std::vector<bool> inconsistent;
  for (size_t n = 0; n < nodes.size(); ++n) {
    const auto [it, added] = landmarkOfRoot.try_emplace(root(n), out.landmarks.size());
    if (added) {
      out.landmarks.emplace_back();
      inconsistent.push_back(false);
    }
    Landmark& l = out.landmarks[it->second];
    for (const LandmarkObservation& o : l.observations)
      if (o.keyframe == nodes[n].keyframe) inconsistent[it->second] = true;
    l.observations.push_back(nodes[n]);
  }
  std::vector<Landmark> kept;
  kept.reserve(out.landmarks.size());
  for (size_t l = 0; l < out.landmarks.size(); ++l) {
    if (inconsistent[l])
      ++out.inconsistentTracks;
    else
      kept.push_back(std::move(out.landmarks[l]));
  }
  out.landmarks = std::move(kept);
  return out;
}

}  // namespace slamdunk
