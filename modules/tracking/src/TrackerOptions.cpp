#include <slamdunk/core/IniOptions.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <cmath>
#include <map>
#include <stdexcept>

namespace slamdunk {

void TrackerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  std::map<std::string, std::string> moved;
  for (const std::string& key : iniKeyNames<LocalMapOptions>()) moved[key] = "local_map";
  loadIniKeys(*this, cfg, section, moved);
  const SectionChecks require(section);
  require(ratioThreshold > 0 && ratioThreshold <= 1, "ratio_threshold must be in (0, 1]");
  require(keypointScaleSigma >= 0 && std::isfinite(keypointScaleSigma),
          "keypoint_scale_sigma must be a finite number >= 0");
  require(depthAlignmentWeight >= 0, "depth_alignment_weight must be >= 0");
  require(depthAlignmentStride >= 1, "depth_alignment_stride must be >= 1");
  require(depthEdgeMaxMatches >= 1, "depth_edge_max_matches must be >= 1");
  require(depthOnly.minAssociatedFraction >= 0 && depthOnly.minAssociatedFraction <= 1,
          "depth_only_min_overlap must be in [0, 1]");
  require(depthOnly.maxRmsResidual > 0, "depth_only_max_residual must be > 0");
  require(depthOnly.minConstraint >= 0, "depth_only_min_constraint must be >= 0");
  require(sensorTiming.rollingShutterMs >= 0 && sensorTiming.rollingShutterMs <= 100,
          "rolling_shutter_ms must be in [0, 100]");
  require(std::abs(sensorTiming.depthTimeOffsetMs) <= 100,
          "depth_time_offset_ms must be in [-100, 100]");
  require(velocityPriorSigmaMetres > 0 && velocityPriorSigmaDegrees > 0,
          "velocity_prior_sigma_m and velocity_prior_sigma_deg must be > 0");
  require(velocityPriorMinSigmaMetres > 0 && velocityPriorMinSigmaDegrees > 0,
          "velocity_prior_min_sigma_m and velocity_prior_min_sigma_deg must be > 0");
  require(velocityPriorMinSigmaMetres <= velocityPriorSigmaMetres &&
              velocityPriorMinSigmaDegrees <= velocityPriorSigmaDegrees,
          "velocity_prior_min_sigma_m/_deg must not exceed velocity_prior_sigma_m/_deg");
  require(ransac.inlierThreshold > 0, "ransac_threshold must be > 0");
  require(ransac.confidence > 0 && ransac.confidence < 1, "ransac_confidence must be in (0, 1)");
  require(ransac.maxIterations >= 1, "ransac_max_iterations must be >= 1");
  require(ransac.minInliers >= 3, "min_inliers must be >= 3");
  require(keyframes.gridCols >= 1 && keyframes.gridRows >= 1, "grid_cols, grid_rows must be >= 1");
  require(keyframes.minOverlap >= 0 && keyframes.minOverlap <= 1,
          "keyframe_overlap must be in [0, 1]");
  require(culling.redundantShare >= 0 && culling.redundantShare <= 1,
          "keyframe_cull_share must be in [0, 1]");
  require(newComponentAfter >= 0, "new_component_after must be >= 0 (0: never)");
  require(!extendMap || localizationOnly, "extend_map goes with localization_only = true");
  require(culling.minObservers >= 1, "keyframe_cull_observers must be >= 1");
}

void TrackerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

}  // namespace slamdunk
