#include <slamdunk/graph/LandmarkTracks.h>
#include <slamdunk/mapping/KeyframeCulling.h>

#include <algorithm>
#include <map>

namespace slamdunk {

namespace {
/// The landmarks around keyframe `id` that it observes: each feature matched further on.
std::vector<const Landmark*> landmarksSeenBy(const LandmarkTracks& tracks, KeyframeId id) {
  std::vector<const Landmark*> out;
  for (const Landmark& l : tracks.landmarks)
    for (const LandmarkObservation& o : l.observations)
      if (o.keyframe == id) {
        out.push_back(&l);
        break;
      }
  return out;
}
}  // namespace

KeyframeCulling::Verdict KeyframeCulling::examine(const KeyframeGraph& graph, KeyframeId id) const {
  Verdict v;
  if (!graph.contains(id)) return v;
  // Its features' tracks, followed two hops away.
  const LandmarkTracks tracks = buildLandmarkTracks(graph.edgesWithin(graph.rings(id, 2)));
  for (const Landmark* l : landmarksSeenBy(tracks, id)) {
    ++v.matchedFeatures;
    if (static_cast<int>(l->observations.size()) - 1 >= options_.minObservers) ++v.coveredFeatures;
  }

  // Its own feature matches: the successor is the neighbour sharing most. The features two or
  // more keyframes matched are joined directly, in a star around the first: the track stays
  // one point (every part of it hung from one of these matches).
  std::map<uint32_t, std::vector<LandmarkObservation>> matchedTo;  // by its feature
  std::map<KeyframeId, size_t> shared;
  for (const KeyframeEdge& e : graph.edgesOf(id)) {
    const bool mineI = e.i == id;
    const KeyframeId other = mineI ? e.j : e.i;
    for (const PointMatch& m : e.matches) {
      if (!m.joinsFeatures()) continue;
      matchedTo[mineI ? m.featureI : m.featureJ].push_back(
          {other, mineI ? m.featureJ : m.featureI, mineI ? m.pointJ : m.pointI});
      ++shared[other];
    }
  }
  size_t mostShared = 0;
  for (const auto& [other, n] : shared)
    if (n > mostShared) {
      mostShared = n;
      v.successor = other;
    }
  std::map<std::pair<KeyframeId, KeyframeId>, std::vector<PointMatch>> rewired;
  for (auto& [feature, seenBy] : matchedTo) {
    std::stable_sort(seenBy.begin(), seenBy.end(),
                     [](const auto& a, const auto& b) { return a.keyframe < b.keyframe; });
    const LandmarkObservation& hub = seenBy.front();
    for (size_t k = 1; k < seenBy.size(); ++k) {
      const LandmarkObservation& o = seenBy[k];
      if (o.keyframe == hub.keyframe) continue;  // a wrong match: the track is dropped anyway
      PointMatch m{hub.point, o.point};
      m.featureI = hub.feature;
      m.featureJ = o.feature;
      rewired[{hub.keyframe, o.keyframe}].push_back(m);
    }
  }
  for (auto& [pair, matches] : rewired) {
    KeyframeEdge e;
    e.i = pair.first;
    e.j = pair.second;
    e.matches = std::move(matches);
    v.rewired.push_back(std::move(e));
  }
  return v;
}

std::vector<KeyframeId> KeyframeCulling::cull(KeyframeGraph& graph,
                                              const std::vector<KeyframeId>& candidates) const {
  std::vector<KeyframeId> culled;
  if (options_.redundantShare <= 0) return culled;
  for (KeyframeId id : candidates) {
    const Verdict v = examine(graph, id);
    if (v.matchedFeatures == 0 || v.coveredShare() < options_.redundantShare) continue;
    graph.cullKeyframe(id, v.successor, v.rewired);
    culled.push_back(id);
  }
  return culled;
}

}  // namespace slamdunk
