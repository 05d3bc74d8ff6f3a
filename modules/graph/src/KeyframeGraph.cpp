#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <algorithm>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

namespace slamdunk {

void KeyframeGraph::addKeyframe(KeyframePtr keyframe, const Pose& T_world_keyframe) {
  std::unique_lock lock(mutex_);
  const KeyframeId id = keyframe->id;
  if (keyframes_.count(id)) throw std::logic_error("keyframe id already in the graph");
  keyframes_[id] = std::move(keyframe);
  poses_[id] = T_world_keyframe;
  adjacency_[id];
}

bool KeyframeGraph::compactDescriptors(KeyframeId id, DescriptorStorage storage) {
  const KeyframePtr kf = keyframe(id);
  if (!kf || kf->features.empty() || kf->features.binary() ||
      descriptorStorage(kf->features.descriptors.type()) >= storage)
    return false;
  auto compact = std::make_shared<Keyframe>(*kf);
  compact->features.descriptors = slamdunk::compactDescriptors(kf->features.descriptors, storage);
  std::unique_lock lock(mutex_);
  const auto it = keyframes_.find(id);
  if (it == keyframes_.end() || it->second != kf) return false;  // culled or replaced meanwhile
  it->second = std::move(compact);
  return true;
}

void KeyframeGraph::addMatches(KeyframeId a, KeyframeId b,
                               const std::vector<PointMatch>& matchesAB) {
  std::unique_lock lock(mutex_);
  addMatchesLocked(a, b, matchesAB);
}

void KeyframeGraph::addMatchesLocked(KeyframeId a, KeyframeId b,
                                     const std::vector<PointMatch>& matchesAB) {
  if (a == b || matchesAB.empty()) return;
  if (!keyframes_.count(a) || !keyframes_.count(b))
    throw std::logic_error("edge between unknown keyframes");
  const bool swap = a > b;
  const EdgeKey key = swap ? EdgeKey{b, a} : EdgeKey{a, b};
  auto [it, inserted] = edges_.try_emplace(key);
  KeyframeEdge& e = it->second;
  if (inserted) {
    e.i = key.first;
    e.j = key.second;
    adjacency_[a].push_back(b);
    adjacency_[b].push_back(a);
  }
  // An edge gets its matches once, when its newer keyframe is spawned (a loop closure may add
  // more): exact capacity, not the up-to-double of push_back's growth (a third of the graph's
  // edge memory on 7-Scenes).
  e.matches.reserve(e.matches.size() + matchesAB.size());
  for (const PointMatch& m : matchesAB) {
    if (!swap) {
      e.matches.push_back(m);
      continue;
    }
    // Stored from the smaller id's side: the information moves into keyframe b's frame
    // through the relative rotation of the two keyframes at this time.
    PointMatch flipped{m.pointJ, m.pointI, m.weight, m.information, m.featureJ, m.featureI};
    const Eigen::Matrix3d R_ba =
        poses_.at(b).linear().transpose() * poses_.at(a).linear();  // b <- a
    flipped.information = R_ba * m.information.matrix() * R_ba.transpose();
    e.matches.push_back(flipped);
  }
}

namespace {
size_t matBytes(const cv::Mat& m) { return m.empty() ? 0 : m.total() * m.elemSize(); }
}  // namespace

GraphMemory KeyframeGraph::memory() const {
  std::shared_lock lock(mutex_);
  GraphMemory m;
  m.keyframes = keyframes_.size();
  for (const auto& [id, kf] : keyframes_) {
    const FeatureSet& f = kf->features;
    m.features += sizeof(Keyframe) + f.keypoints.capacity() * sizeof(cv::KeyPoint) +
                  matBytes(f.descriptors) + f.points.capacity() * sizeof(Eigen::Vector3d);
    if (const auto r = refined_.find(id); r != refined_.end())
      m.features += r->second->capacity() * sizeof(Eigen::Vector3d);
    m.depthSmall += matBytes(kf->depthSmall);
    m.images += matBytes(kf->colour) + matBytes(kf->depth);
  }
  for (const auto& [key, e] : edges_)
    m.edges += sizeof(KeyframeEdge) + e.matches.capacity() * sizeof(PointMatch);
  return m;
}

size_t KeyframeGraph::keyframeCount() const {
  std::shared_lock lock(mutex_);
  return keyframes_.size();
}

size_t KeyframeGraph::edgeCount() const {
  std::shared_lock lock(mutex_);
  return edges_.size();
}

bool KeyframeGraph::contains(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  return keyframes_.count(id) > 0;
}

KeyframePtr KeyframeGraph::keyframe(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  const auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second;
}

void KeyframeGraph::cullKeyframe(KeyframeId id, KeyframeId successor,
                                 const std::vector<KeyframeEdge>& rewired) {
  std::unique_lock lock(mutex_);
  if (!keyframes_.count(id) || !keyframes_.count(successor) || id == successor)
    throw std::logic_error("cullKeyframe(): unknown keyframe or successor");
  culled_[id] = {successor, poses_.at(successor).inverse() * poses_.at(id)};
  for (KeyframeId n : adjacency_.at(id)) {
    edges_.erase(id < n ? EdgeKey{id, n} : EdgeKey{n, id});
    auto& back = adjacency_.at(n);
    back.erase(std::remove(back.begin(), back.end(), id), back.end());
  }
  adjacency_.erase(id);
  keyframes_.erase(id);
  poses_.erase(id);
  refined_.erase(id);
  for (const KeyframeEdge& e : rewired) addMatchesLocked(e.i, e.j, e.matches);
}

size_t KeyframeGraph::culledCount() const {
  std::shared_lock lock(mutex_);
  return culled_.size();
}

Pose KeyframeGraph::pose(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  if (auto p = poseLocked(id)) return *p;
  throw std::out_of_range("pose(): unknown keyframe " + std::to_string(id));
}

std::optional<Pose> KeyframeGraph::findPose(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  return poseLocked(id);
}

std::optional<Pose> KeyframeGraph::poseLocked(KeyframeId id) const {
  if (const auto it = poses_.find(id); it != poses_.end()) return it->second;
  const auto c = culled_.find(id);
  if (c == culled_.end()) return std::nullopt;
  const auto successor = poseLocked(c->second.successor);
  return successor ? std::optional<Pose>(*successor * c->second.successorToCulled) : std::nullopt;
}

std::vector<KeyframeId> KeyframeGraph::ids() const {
  std::shared_lock lock(mutex_);
  std::vector<KeyframeId> out;
  for (const auto& kv : keyframes_) out.push_back(kv.first);
  return out;
}

std::map<KeyframeId, Pose> KeyframeGraph::poses() const {
  std::shared_lock lock(mutex_);
  return poses_;
}

void KeyframeGraph::setPoses(const std::map<KeyframeId, Pose>& poses,
                             const PointRefinements& refined) {
  // The new point vectors are built before taking the lock: readers wait only for the swap.
  std::map<KeyframeId, RefinedPoints> replacements;
  for (const auto& [id, changes] : refined) {
    const KeyframePtr kf = keyframe(id);
    if (!kf || isAnchored(id)) continue;  // culled meanwhile, or held
    const RefinedPoints old = refinedPoints(id);
    auto points = std::make_shared<std::vector<Eigen::Vector3d>>(old ? *old : kf->features.points);
    for (const auto& [feature, p] : changes) points->at(feature) = p;
    replacements[id] = std::move(points);
  }
  std::unique_lock lock(mutex_);
  for (const auto& [id, p] : poses)
    if (const auto it = poses_.find(id); it != poses_.end() && !anchored_.count(id)) it->second = p;
  for (auto& [id, points] : replacements)
    if (keyframes_.count(id)) refined_[id] = std::move(points);
}

void KeyframeGraph::applyCorrection(const std::map<KeyframeId, Pose>& poses, KeyframeId newest) {
  std::unique_lock lock(mutex_);
  const auto corrected = poses.find(newest);
  const auto before = poses_.find(newest);
  // Keyframes added since the snapshot move with `newest`; an anchored one does not move.
  if (corrected != poses.end() && before != poses_.end() && !anchored_.count(newest)) {
    const Pose carry = corrected->second * before->second.inverse();
    for (auto it = poses_.upper_bound(newest); it != poses_.end(); ++it)
      if (!anchored_.count(it->first)) it->second = orthonormalized(carry * it->second);
  }
  for (const auto& [id, p] : poses)
    if (const auto it = poses_.find(id); it != poses_.end() && !anchored_.count(id)) it->second = p;
}

std::map<KeyframeId, int> KeyframeGraph::component(KeyframeId id) const {
  return rings(id, std::numeric_limits<int>::max());
}

bool KeyframeGraph::connected(KeyframeId a, KeyframeId b) const {
  return hopDistance(a, b, std::numeric_limits<int>::max()) >= 0;
}

void KeyframeGraph::anchor(const std::vector<KeyframeId>& ids) {
  std::unique_lock lock(mutex_);
  anchored_.insert(ids.begin(), ids.end());
}

bool KeyframeGraph::isAnchored(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  return anchored_.count(id) > 0;
}

std::set<KeyframeId> KeyframeGraph::anchoredIds() const {
  std::shared_lock lock(mutex_);
  return anchored_;
}

RefinedPoints KeyframeGraph::refinedPoints(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  const auto it = refined_.find(id);
  return it == refined_.end() ? nullptr : it->second;
}

std::vector<KeyframeId> KeyframeGraph::neighbours(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  auto n = adjacency_.at(id);
  std::sort(n.begin(), n.end());
  return n;
}

std::vector<KeyframeEdge> KeyframeGraph::edgesOf(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  std::vector<KeyframeEdge> out;
  for (KeyframeId n : adjacency_.at(id))
    out.push_back(edges_.at(id < n ? EdgeKey{id, n} : EdgeKey{n, id}));
  std::sort(out.begin(), out.end(), [](const KeyframeEdge& a, const KeyframeEdge& b) {
    return std::make_pair(a.i, a.j) < std::make_pair(b.i, b.j);
  });
  return out;
}

std::map<KeyframeId, int> KeyframeGraph::ringsLocked(KeyframeId root, int maxRing) const {
  std::map<KeyframeId, int> ring{{root, 0}};
  std::deque<KeyframeId> queue{root};
  while (!queue.empty()) {
    const KeyframeId v = queue.front();
    queue.pop_front();
    const int r = ring[v];
    if (r >= maxRing) continue;
    auto next = adjacency_.at(v);
    std::sort(next.begin(), next.end());  // deterministic visiting order
    for (KeyframeId n : next)
      if (ring.emplace(n, r + 1).second) queue.push_back(n);
  }
  return ring;
}

std::map<KeyframeId, int> KeyframeGraph::rings(KeyframeId root, int maxRing) const {
  std::shared_lock lock(mutex_);
  if (!keyframes_.count(root)) return {};
  return ringsLocked(root, maxRing);
}

int KeyframeGraph::hopDistance(KeyframeId a, KeyframeId b, int maxHops) const {
  std::shared_lock lock(mutex_);
  if (!keyframes_.count(a) || !keyframes_.count(b)) return -1;
  const auto r = ringsLocked(a, maxHops);
  const auto it = r.find(b);
  return it == r.end() ? -1 : it->second;
}

std::vector<KeyframeEdge> KeyframeGraph::edgesWithin(
    const std::map<KeyframeId, int>& vertices) const {
  std::shared_lock lock(mutex_);
  std::vector<KeyframeEdge> out;
  for (const auto& [key, e] : edges_)
    if (vertices.count(key.first) && vertices.count(key.second)) out.push_back(e);
  return out;
}

std::vector<KeyframeEdge> KeyframeGraph::allEdges() const {
  std::shared_lock lock(mutex_);
  std::vector<KeyframeEdge> out;
  for (const auto& kv : edges_) out.push_back(kv.second);
  return out;
}

std::vector<std::pair<KeyframeId, KeyframeId>> KeyframeGraph::edgeIds() const {
  std::shared_lock lock(mutex_);
  std::vector<std::pair<KeyframeId, KeyframeId>> out;
  out.reserve(edges_.size());
  for (const auto& kv : edges_) out.push_back(kv.first);
  return out;
}

std::shared_ptr<KeyframeGraph> KeyframeGraph::snapshot() const {
  auto copy = std::make_shared<KeyframeGraph>();
  std::shared_lock lock(mutex_);
  copy->keyframes_ = keyframes_;
  copy->poses_ = poses_;
  copy->edges_ = edges_;
  copy->adjacency_ = adjacency_;
  copy->refined_ = refined_;
  copy->culled_ = culled_;
  copy->anchored_ = anchored_;
  return copy;
}

std::map<KeyframeId, Pose> movedRigidly(const std::map<KeyframeId, Pose>& poses, const Pose& motion,
                                        const std::map<KeyframeId, int>* ids) {
  std::map<KeyframeId, Pose> moved;
  for (const auto& [id, pose] : poses)
    if (!ids || ids->count(id)) moved[id] = orthonormalized(motion * pose);
  return moved;
}

}  // namespace slamdunk
