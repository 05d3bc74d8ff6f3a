#include "LocalProblem.h"

#include <cmath>
#include <numeric>

namespace slamdunk {

size_t LocalProblem::matchCount() const {
  size_t n = 0;
  for (const KeyframeEdge& e : edges) n += e.matches.size();
  return n;
}

namespace {
void snapshotFocalLengths(const KeyframeGraph& graph, LocalProblem& p) {
  for (auto it = p.poses.begin(); it != p.poses.end();) {
    const KeyframePtr kf = graph.keyframe(it->first);
    if (!kf) {  // culled meanwhile (live): its edges go too (cleanMatches)
      p.fixed.erase(it->first);
      it = p.poses.erase(it);
      continue;
    }
    p.focalLengths[it->first] = Eigen::Vector2d(kf->intrinsics.fx, kf->intrinsics.fy);
    ++it;
  }
}
}  // namespace

LocalProblem snapshotRings(const KeyframeGraph& graph, KeyframeId root, int rings) {
  // Three short locked reads; keyframes/edges added in between are simply not seen this time.
  const std::map<KeyframeId, int> ring = graph.rings(root, rings);
  LocalProblem p;
  p.edges = graph.edgesWithin(ring);
  const std::set<KeyframeId> anchored = graph.anchoredIds();
  for (const auto& [id, r] : ring) {
    p.poses[id] = graph.pose(id);
    if (r >= rings || anchored.count(id)) p.fixed.insert(id);
  }
  snapshotFocalLengths(graph, p);
  return p;
}

LocalProblem snapshotAll(const KeyframeGraph& graph) {
  LocalProblem p;
  p.edges = graph.allEdges();
  p.poses = graph.poses();
  for (KeyframeId id : graph.anchoredIds())
    if (p.poses.count(id)) p.fixed.insert(id);
  snapshotFocalLengths(graph, p);
  return p;
}

namespace {
bool isFinite(const PointMatch& m) {
  return m.pointI.allFinite() && m.pointJ.allFinite() && std::isfinite(m.weight);
}
}  // namespace

void cleanMatches(LocalProblem& p, double minWeight) {
  std::vector<KeyframeEdge> kept;
  std::set<KeyframeId> touched;
  for (KeyframeEdge& e : p.edges) {
    // Edges whose endpoints are both fixed add a constant to the cost: skip them.
    if (!p.poses.count(e.i) || !p.poses.count(e.j)) continue;
    if (p.fixed.count(e.i) && p.fixed.count(e.j)) continue;
    std::vector<PointMatch> good;
    good.reserve(e.matches.size());
    for (const PointMatch& m : e.matches) {
      if (!isFinite(m) || m.weight < 0) {
        ++p.invalidMatches;
      } else if (m.weight == 0 || m.weight < minWeight) {
        ++p.droppedMatches;  // weight 0 contributes nothing to Eq. 4
      } else {
        good.push_back(m);
      }
    }
    if (good.empty()) continue;
    e.matches = std::move(good);
    touched.insert(e.i);
    touched.insert(e.j);
    kept.push_back(std::move(e));
  }
  p.edges = std::move(kept);
  for (auto it = p.poses.begin(); it != p.poses.end();)
    it = touched.count(it->first) ? std::next(it) : p.poses.erase(it);
  for (auto it = p.fixed.begin(); it != p.fixed.end();)
    it = touched.count(*it) ? std::next(it) : p.fixed.erase(it);
}

void fixGauge(LocalProblem& p, const KeyframeId* preferred) {
  // Union-find over the problem's vertices (few dozen locally; the whole map for optimizeAll).
  std::map<KeyframeId, KeyframeId> parent;
  for (const auto& kv : p.poses) parent[kv.first] = kv.first;
  auto find = [&](KeyframeId v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const KeyframeEdge& e : p.edges) {
    const KeyframeId a = find(e.i), b = find(e.j);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  // Component representative -> vertex to fix (if the component has no fixed vertex yet).
  std::map<KeyframeId, bool> anchored;
  std::map<KeyframeId, KeyframeId> choice;
  for (const auto& kv : p.poses) {  // ascending ids: the first seen is the smallest
    const KeyframeId id = kv.first, c = find(id);
    anchored[c] = anchored[c] || p.fixed.count(id) > 0;
    if (!choice.count(c) || (preferred && id == *preferred)) choice[c] = id;
  }
  for (const auto& [c, isAnchored] : anchored)
    if (!isAnchored) p.fixed.insert(choice[c]);
}

}  // namespace slamdunk
