#pragma once
// Section [loop_closing]: place recognition beyond the active window and the global
// correction of an accepted loop.

#include <slamdunk/optimization/PoseGraphOptimizer.h>
#include <slamdunk/tracking/RansacAbsoluteOrientation.h>

#include <mrpt/config/CLoadableOptions.h>

#include <string>

namespace slamdunk {

struct LoopClosingOptions : public mrpt::config::CLoadableOptions {
  bool enabled = true;
  /// The words are learned from the descriptors of the map's first this many keyframes, and
  /// learned again (every keyframe indexed again) each time the map has grown fourfold since.
  int vocabularyKeyframes = 10;
  int vocabularyBranching = 10;  ///< children of each node of the words' k-means tree
  int vocabularyLevels = 4;      ///< its depth: up to branching^levels words
  /// Candidates are at least this many graph hops from the new keyframe (or unconnected):
  /// nearer keyframes are the active window's, whose loops the tracker closes itself.
  int minHops = 6;
  int maxCandidates = 3;  ///< best-scoring candidates verified per keyframe
  /// A candidate scores at least this share of the new keyframe's lowest score with the
  /// keyframes it is linked to (the same place, seen a moment ago).
  double minScoreShare = 0.8;
  double ratioThreshold = 0.8;  ///< descriptor ratio test of the verification
  int minInliers = 30;          ///< RANSAC inliers of a verified candidate
  /// Consecutive keyframes whose verified loops agree before one is accepted.
  int consistentKeyframes = 2;
  double consistencyTranslation = 0.1;  ///< metres: how far two loops' measures may disagree
  double consistencyAngleDeg = 3.0;
  /// A loop may correct the map by at most this share of the path the keyframes travelled
  /// between its two ends, plus 0.1 m: odometry drifts by a few percent, and a place that looks
  /// the same farther away than that (a second identical room) is another place.
  double maxDriftShare = 0.1;
  /// A loop between two unconnected components of the map (a session that started where the
  /// loaded map does not reach) has no path to bound its correction: it joins them once this
  /// many consecutive keyframes agree.
  int joinConsistentKeyframes = 3;
  RansacOptions ransac;  ///< the tracker's ([tracker] ransac_*)
  PoseGraphOptions poseGraph;

  /// Its INI keys (section [loop_closing]), listed once for loading and saving.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("enabled", o.enabled);
    k("vocabulary_keyframes", o.vocabularyKeyframes);
    k("vocabulary_branching", o.vocabularyBranching);
    k("vocabulary_levels", o.vocabularyLevels);
    k("min_hops", o.minHops);
    k("max_candidates", o.maxCandidates);
    k("min_score_share", o.minScoreShare);
    k("ratio_threshold", o.ratioThreshold);
    k("min_inliers", o.minInliers);
    k("consistent_keyframes", o.consistentKeyframes);
    k("consistency_translation", o.consistencyTranslation);
    k("consistency_angle_deg", o.consistencyAngleDeg);
    k("max_drift_share", o.maxDriftShare);
    k("join_consistent_keyframes", o.joinConsistentKeyframes);
    k("pose_graph_translation_sigma", o.poseGraph.translationSigma);
    k("pose_graph_rotation_sigma", o.poseGraph.rotationSigma);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
  /// Throws std::invalid_argument naming the section when a value is out of range.
  void validate(const std::string& section = "loop_closing") const;
};

}  // namespace slamdunk
