#include <slamdunk/core/IniOptions.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <cmath>
#include <map>
#include <stdexcept>

namespace slamdunk {

EdgeInformation edgeInformationFromString(const std::string& name) {
  if (name == "paper") return EdgeInformation::Paper;
  if (name == "isotropic") return EdgeInformation::Isotropic;
  if (name == "anisotropic") return EdgeInformation::Anisotropic;
  throw std::invalid_argument("edge_information = '" + name +
                              "' (choose paper, isotropic or anisotropic)");
}

std::string toString(EdgeInformation e) {
  switch (e) {
    case EdgeInformation::Paper:
      return "paper";
    case EdgeInformation::Isotropic:
      return "isotropic";
    case EdgeInformation::Anisotropic:
      return "anisotropic";
  }
  return "?";
}

namespace {
template <class Self, class Keys>
void forEachKey(Self& o, Keys& k) {
  k("ratio_threshold", o.ratioThreshold);
  k("loop_hop_threshold", o.loopHopThreshold);
  k("loop_min_inliers", o.loopMinInliers);
  k("edge_min_matches", o.edgeMinMatches);
  k("min_features", o.minFeatures);
  k("relocalize_after", o.relocalizeAfter);
  k("relocalize_min_inliers", o.relocalizeMinInliers);
  k("max_translation_jump", o.maxTranslationJump);
  k("keep_keyframe_images", o.keepKeyframeImages);
  k("weighted_refit", o.weightedRefit);
  k.choice("edge_information", o.edgeInformation, edgeInformationFromString);
  k("keypoint_scale_sigma", o.keypointScaleSigma);
  k("anisotropic_refinement", o.anisotropicRefinement);
  k("depth_alignment_weight", o.depthAlignmentWeight);
  k("depth_alignment_stride", o.depthAlignmentStride);
  k("depth_alignment_max_distance", o.depthAlignmentMaxDistance);
  k("depth_alignment_max_depth", o.depthAlignmentMaxDepth);
  k("depth_alignment_central_normals", o.depthAlignmentCentralNormals);
  k("depth_edges", o.depthEdges);
  k("depth_edge_max_matches", o.depthEdgeMaxMatches);
  k("depth_edge_weight", o.depthEdgeWeight);
  k("depth_only_fallback", o.depthOnlyFallback);
  k("estimate_keypoint_noise", o.noiseEstimation.enabled);
  k("estimate_rolling_shutter", o.rollingShutterEstimation.enabled);
  k("estimate_frame_velocity", o.estimateFrameVelocity);
  k("velocity_prior_sigma_m", o.velocityPriorSigmaMetres);
  k("velocity_prior_sigma_deg", o.velocityPriorSigmaDegrees);
  k("velocity_prior_adaptive", o.adaptiveVelocityPrior);
  k("velocity_prior_min_sigma_m", o.velocityPriorMinSigmaMetres);
  k("velocity_prior_min_sigma_deg", o.velocityPriorMinSigmaDegrees);
  DepthOnlyOptions::forEachKey(o.depthOnly, k);
  SensorTimingOptions::forEachKey(o.sensorTiming, k);
  RansacOptions::forEachKey(o.ransac, k);
  KeyframePolicyOptions::forEachKey(o.keyframes, k);
}
}  // namespace

void TrackerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  IniSectionReader r(cfg, section);
  forEachKey(*this, r);
  std::map<std::string, std::string> moved;
  for (const std::string& key : LocalMapOptions::keyNames()) moved[key] = "local_map";
  r.rejectUnknownKeys(moved);

  auto require = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument("[" + section + "] " + what);
  };
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
}

void TrackerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& section) const {
  IniSectionWriter w(cfg, section);
  forEachKey(*this, w);
}

}  // namespace slamdunk
