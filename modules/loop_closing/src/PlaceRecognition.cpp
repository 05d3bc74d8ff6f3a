#include <slamdunk/features/CompactDescriptors.h>
#include <slamdunk/loop_closing/PlaceRecognition.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>

namespace slamdunk {

namespace {
/// Descriptors of many keyframes are sampled down to this many rows to learn the words.
constexpr int kMaxLearningRows = 20000;
/// Lloyd rounds per node of the words' tree: the clusters matter less than their number.
constexpr int kLearningRounds = 5;
/// A join is checked against the map's keyframes this close to where it puts the new
/// component's keyframes: views this alike must match if the join is right.
constexpr double kJoinCheckMetres = 0.3;
constexpr double kJoinCheckDegrees = 15.0;
constexpr int kJoinChecks = 8;  ///< at most this many keyframes of the new component checked
}  // namespace

PlaceRecognition::PlaceRecognition(const LoopClosingOptions& options) : options_(options) {
  options_.validate();
}

void PlaceRecognition::learnWords(const KeyframeGraph& graph) {
  std::vector<KeyframePtr> keyframes;
  int rows = 0;
  for (KeyframeId id : graph.ids())
    if (KeyframePtr kf = graph.keyframe(id); kf && !kf->features.descriptors.empty()) {
      rows += kf->features.descriptors.rows;
      keyframes.push_back(std::move(kf));
    }
  if (keyframes.empty()) return;
  const int step = std::max(1, rows / kMaxLearningRows);
  std::vector<cv::Mat> sampled;
  int k = 0;
  for (const KeyframePtr& kf : keyframes) {
    const cv::Mat rowsOfKeyframe = matchableDescriptors(kf->features.descriptors);
    for (int r = 0; r < rowsOfKeyframe.rows; ++r, ++k)
      if (k % step == 0) sampled.push_back(rowsOfKeyframe.row(r));
  }
  cv::Mat learning;
  cv::vconcat(sampled, learning);
  Vocabulary words =
      Vocabulary::learn(learning, options_.vocabularyBranching, options_.vocabularyLevels,
                        kLearningRounds, options_.ransac.seed);
  std::vector<std::vector<uint32_t>> perKeyframe;
  for (const KeyframePtr& kf : keyframes)
    perKeyframe.push_back(words.words(kf->features.descriptors));
  index_ = PlaceIndex(std::move(words), perKeyframe);
  for (const KeyframePtr& kf : keyframes)
    index_.add(kf->id, index_.describe(kf->features.descriptors));
  wordsLearnedAt_ = keyframes.size();
}

std::vector<KeyframeId> PlaceRecognition::candidates(const KeyframeGraph& graph, KeyframeId id,
                                                     const BagOfWords& bag) const {
  // The lowest score of the keyframes the new one is linked to: what "the same place" scores
  // here (scenes and vocabularies differ too much for one fixed threshold).
  double linkedScore = -1;
  const std::vector<std::pair<KeyframeId, double>> scores = index_.query(bag);
  for (KeyframeId n : graph.neighbours(id))
    for (const auto& [other, score] : scores)
      if (other == n) linkedScore = linkedScore < 0 ? score : std::min(linkedScore, score);
  if (linkedScore < 0) return {};  // nothing to compare with (a new map, or just relocalized)
  const std::map<KeyframeId, int> near = graph.rings(id, options_.minHops - 1);
  std::vector<std::pair<KeyframeId, double>> found;
  for (const auto& [other, score] : scores)
    if (!near.count(other) && other != id && score >= options_.minScoreShare * linkedScore)
      found.emplace_back(other, score);
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::vector<KeyframeId> out;
  for (size_t i = 0; i < found.size() && static_cast<int>(i) < options_.maxCandidates; ++i)
    out.push_back(found[i].first);
  return out;
}

std::optional<LoopHypothesis> PlaceRecognition::verify(const Keyframe& query,
                                                       const Keyframe& candidate) const {
  const FeatureSet& q = query.features;
  const FeatureSet& c = candidate.features;
  if (q.size() < 3 || c.size() < 3 || q.binary() != c.binary()) return {};
  cv::BFMatcher matcher(q.binary() ? cv::NORM_HAMMING : cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(matchableDescriptors(q.descriptors), matchableDescriptors(c.descriptors), knn,
                   2);
  std::vector<LoopHypothesis::Match> matches;
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& m : knn) {
    if (m.size() < 2 || !(m[1].distance > 0)) continue;
    const double ratio = m[0].distance / m[1].distance;
    if (ratio >= options_.ratioThreshold) continue;
    matches.push_back(
        {static_cast<uint32_t>(m[0].trainIdx), static_cast<uint32_t>(m[0].queryIdx), ratio});
    src.push_back(q.points[m[0].queryIdx]);
    dst.push_back(c.points[m[0].trainIdx]);
  }
  if (static_cast<int>(matches.size()) < options_.minInliers) return {};
  RansacOptions ransac = options_.ransac;
  ransac.minInliers = options_.minInliers;
  const RansacResult fit = ransacAbsoluteOrientation(src, dst, ransac);
  if (!fit.success || static_cast<int>(fit.inlierCount) < options_.minInliers) return {};
  LoopHypothesis h;
  h.query = query.id;
  h.candidate = candidate.id;
  h.T_candidate_query = fit.transform;
  for (size_t i = 0; i < matches.size(); ++i)
    if (fit.inliers[i]) h.inliers.push_back(matches[i]);
  return h;
}

bool PlaceRecognition::agree(const LoopHypothesis& a, const LoopHypothesis& b,
                             const KeyframeGraph& graph) const {
  // The motion from a's keyframe to b's, by the map (odometry) and by the two loops.
  const Pose byMap = graph.pose(a.query).inverse() * graph.pose(b.query);
  const Pose byLoops = (graph.pose(a.candidate) * a.T_candidate_query).inverse() *
                       (graph.pose(b.candidate) * b.T_candidate_query);
  return translationDistance(byMap, byLoops) <= options_.consistencyTranslation &&
         rotationDistance(byMap, byLoops) * 180.0 / M_PI <= options_.consistencyAngleDeg;
}

bool PlaceRecognition::plausibleDrift(const LoopHypothesis& h, const KeyframeGraph& graph) const {
  // The path of the keyframes made between the loop's ends (ids grow with time).
  double path = 0;
  std::optional<Eigen::Vector3d> last;
  const std::vector<KeyframeId> ids = graph.ids();  // sorted
  for (auto it = std::lower_bound(ids.begin(), ids.end(), h.candidate);
       it != ids.end() && *it <= h.query; ++it) {
    const Eigen::Vector3d p = graph.pose(*it).translation();
    if (last) path += (p - *last).norm();
    last = p;
  }
  const Pose corrected = graph.pose(h.candidate) * h.T_candidate_query;
  return translationDistance(corrected, graph.pose(h.query)) <= 0.1 + options_.maxDriftShare * path;
}

bool PlaceRecognition::joinContradicted(const LoopHypothesis& h, const KeyframeGraph& graph) const {
  const std::map<KeyframeId, int> joining = graph.component(h.query);
  const std::map<KeyframeId, Pose> poses = graph.poses();
  const Pose toMap = poses.at(h.candidate) * h.T_candidate_query * poses.at(h.query).inverse();
  // The map's keyframes by cells of the check's distance: those within it of a point are in
  // the 27 cells around the point's (each cell's ids ascending, as the poses are).
  using Cell = std::array<int64_t, 3>;
  auto cellOf = [](const Eigen::Vector3d& p) {
    return Cell{int64_t(std::floor(p.x() / kJoinCheckMetres)),
                int64_t(std::floor(p.y() / kJoinCheckMetres)),
                int64_t(std::floor(p.z() / kJoinCheckMetres))};
  };
  std::map<Cell, std::vector<KeyframeId>> cells;
  for (const auto& [id, pose] : poses)
    if (!joining.count(id)) cells[cellOf(pose.translation())].push_back(id);
  int checked = 0, failed = 0;
  for (const auto& [id, ring] : joining) {  // the oldest first: the farthest from the join
    const Pose inMap = toMap * poses.at(id);
    std::vector<KeyframeId> near;
    const Cell c = cellOf(inMap.translation());
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz)
          if (auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz}); it != cells.end())
            near.insert(near.end(), it->second.begin(), it->second.end());
    std::sort(near.begin(), near.end());  // ties go to the newest, as over all poses in order
    std::optional<KeyframeId> nearest;
    double nearestMetres = kJoinCheckMetres;
    for (KeyframeId other : near) {
      const Pose& pose = poses.at(other);
      if (rotationDistance(pose, inMap) * 180.0 / M_PI > kJoinCheckDegrees) continue;
      const double metres = translationDistance(pose, inMap);
      if (metres <= nearestMetres) nearest = other, nearestMetres = metres;
    }
    const KeyframePtr mine = graph.keyframe(id);
    const KeyframePtr theirs = nearest ? graph.keyframe(*nearest) : nullptr;
    if (!mine || !theirs) continue;
    ++checked;
    const std::optional<LoopHypothesis> seen = verify(*mine, *theirs);
    const Pose expected = poses.at(*nearest).inverse() * inMap;
    if (!seen ||
        translationDistance(seen->T_candidate_query, expected) > options_.consistencyTranslation ||
        rotationDistance(seen->T_candidate_query, expected) * 180.0 / M_PI >
            options_.consistencyAngleDeg)
      ++failed;
    if (checked == kJoinChecks) break;
  }
  return 3 * failed > checked;
}

PlaceRecognition::Detection PlaceRecognition::keyframeAdded(const KeyframeGraph& graph,
                                                            KeyframeId id) {
  Detection d;
  const std::optional<KeyframeId> previous = lastKeyframe_;
  lastKeyframe_ = id;
  const KeyframePtr kf = graph.keyframe(id);
  if (!options_.enabled || !kf) return d;
  const size_t keyframes = graph.keyframeCount();
  if (keyframes >= static_cast<size_t>(options_.vocabularyKeyframes) &&
      (!index_.ready() || keyframes >= 4 * wordsLearnedAt_)) {
    learnWords(graph);  // indexes every keyframe, this one too
    chain_.clear();
    return d;
  }
  if (!index_.ready()) return d;
  // Keyframes a busy back end skipped are indexed all the same (looked up: only the newest).
  for (KeyframeId other : graph.ids())
    if (other < id && !index_.contains(other))
      if (const KeyframePtr skipped = graph.keyframe(other))
        index_.add(other, index_.describe(skipped->features.descriptors));

  BagOfWords bag = index_.describe(kf->features.descriptors);
  std::optional<LoopHypothesis> best;
  for (KeyframeId c : candidates(graph, id, bag)) {
    const KeyframePtr candidate = graph.keyframe(c);
    if (!candidate) continue;
    ++d.candidatesVerified;
    std::optional<LoopHypothesis> h = verify(*kf, *candidate);
    if (h) h->joins = !graph.connected(id, c);
    if (h && !h->joins && !plausibleDrift(*h, graph)) {
      h.reset();
      ++d.candidatesRefused;
    }
    if (h && (!best || h->inliers.size() > best->inliers.size())) best = std::move(h);
  }
  index_.add(id, std::move(bag));
  if (best) best->score = index_.score(id, best->candidate);

  const bool continues = best && !chain_.empty() && previous && chain_.back().query == *previous &&
                         agree(chain_.back(), *best, graph);
  if (!continues) chain_.clear();
  if (best) chain_.push_back(std::move(*best));
  // Without a path between them, only more agreeing keyframes tell another place from this one.
  const bool joins =
      std::any_of(chain_.begin(), chain_.end(), [](const auto& h) { return h.joins; });
  const int needed = joins ? options_.joinConsistentKeyframes : options_.consistentKeyframes;
  if (static_cast<int>(chain_.size()) >= needed) {
    if (joins && joinContradicted(chain_.back(), graph)) {
      ++d.joinsRefused;
      chain_.clear();
      return d;
    }
    d.accepted = std::move(chain_);
    chain_.clear();
  }
  return d;
}

}  // namespace slamdunk
