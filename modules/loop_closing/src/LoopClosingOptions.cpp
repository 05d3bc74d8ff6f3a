#include <slamdunk/core/IniOptions.h>
#include <slamdunk/loop_closing/LoopClosingOptions.h>

#include <cmath>

namespace slamdunk {

void LoopClosingOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                            const std::string& section) {
  loadIniKeys(*this, cfg, section);
  validate(section);
}

void LoopClosingOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                          const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

void LoopClosingOptions::validate(const std::string& section) const {
  const SectionChecks require(section);
  require(vocabularyKeyframes >= 1, "vocabulary_keyframes must be >= 1");
  require(vocabularyBranching >= 2 && vocabularyBranching <= 256,
          "vocabulary_branching must be in [2, 256]");
  require(vocabularyLevels >= 1 && vocabularyLevels <= 8, "vocabulary_levels must be in [1, 8]");
  require(minHops >= 1, "min_hops must be >= 1");
  require(maxCandidates >= 1, "max_candidates must be >= 1");
  require(minScoreShare >= 0 && std::isfinite(minScoreShare), "min_score_share must be >= 0");
  require(ratioThreshold > 0 && ratioThreshold <= 1, "ratio_threshold must be in (0, 1]");
  require(minInliers >= 3, "min_inliers must be >= 3");
  require(consistentKeyframes >= 1, "consistent_keyframes must be >= 1");
  require(consistencyTranslation > 0, "consistency_translation must be > 0");
  require(consistencyAngleDeg > 0, "consistency_angle_deg must be > 0");
  require(maxDriftShare > 0, "max_drift_share must be > 0");
  require(joinConsistentKeyframes >= 1, "join_consistent_keyframes must be >= 1");
  require(poseGraph.translationSigma > 0, "pose_graph_translation_sigma must be > 0");
  require(poseGraph.rotationSigma > 0, "pose_graph_rotation_sigma must be > 0");
}

}  // namespace slamdunk
