#include <slamdunk/core/IniOptions.h>
#include <slamdunk/tracking/TrackerOptions.h>

#include <cmath>
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

LocalMapOptions TrackerOptions::localMapOptions() const {
  LocalMapOptions o;
  o.windowSize = windowSize;
  o.windowShift = windowShift;
  o.windowShiftAngle = windowShiftAngle;
  o.backgroundPreparation = poolInBackground;
  o.handoverFrames = poolHandoverFrames;
  o.handoverFeaturesPerFrame = poolHandoverFeaturesPerFrame;
  o.pool = pool;
  return o;
}

void TrackerOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                        const std::string& section) {
  IniSectionReader r(cfg, section);
  windowSize = r.readDouble("window_size", windowSize);
  windowShift = r.readDouble("window_shift", windowShift);
  windowShiftAngle = r.readDouble("window_shift_angle", windowShiftAngle);
  poolInBackground = r.readBool("pool_in_background", poolInBackground);
  poolHandoverFrames = r.readInt("pool_handover_frames", poolHandoverFrames);
  poolHandoverFeaturesPerFrame =
      r.readInt("pool_handover_features_per_frame", poolHandoverFeaturesPerFrame);
  ratioThreshold = r.readDouble("ratio_threshold", ratioThreshold);
  loopHopThreshold = r.readInt("loop_hop_threshold", loopHopThreshold);
  loopMinInliers = r.readInt("loop_min_inliers", loopMinInliers);
  edgeMinMatches = r.readInt("edge_min_matches", edgeMinMatches);
  minFeatures = r.readInt("min_features", minFeatures);
  relocalizeAfter = r.readInt("relocalize_after", relocalizeAfter);
  relocalizeMinInliers = r.readInt("relocalize_min_inliers", relocalizeMinInliers);
  maxTranslationJump = r.readDouble("max_translation_jump", maxTranslationJump);
  keepKeyframeImages = r.readBool("keep_keyframe_images", keepKeyframeImages);
  weightedRefit = r.readBool("weighted_refit", weightedRefit);
  edgeInformation =
      edgeInformationFromString(r.readString("edge_information", toString(edgeInformation)));
  keypointScaleSigma = r.readDouble("keypoint_scale_sigma", keypointScaleSigma);
  anisotropicRefinement = r.readBool("anisotropic_refinement", anisotropicRefinement);
  depthAlignmentWeight = r.readDouble("depth_alignment_weight", depthAlignmentWeight);
  depthAlignmentStride = r.readInt("depth_alignment_stride", depthAlignmentStride);
  depthAlignmentMaxDistance =
      r.readDouble("depth_alignment_max_distance", depthAlignmentMaxDistance);
  depthAlignmentMaxDepth = r.readDouble("depth_alignment_max_depth", depthAlignmentMaxDepth);
  depthAlignmentCentralNormals =
      r.readBool("depth_alignment_central_normals", depthAlignmentCentralNormals);
  depthEdges = r.readBool("depth_edges", depthEdges);
  depthEdgeMaxMatches = r.readInt("depth_edge_max_matches", depthEdgeMaxMatches);
  depthEdgeWeight = r.readDouble("depth_edge_weight", depthEdgeWeight);
  depthOnlyFallback = r.readBool("depth_only_fallback", depthOnlyFallback);
  noiseEstimation.enabled = r.readBool("estimate_keypoint_noise", noiseEstimation.enabled);
  rollingShutterEstimation.enabled =
      r.readBool("estimate_rolling_shutter", rollingShutterEstimation.enabled);
  sensorTiming.rollingShutterMs = r.readDouble("rolling_shutter_ms", sensorTiming.rollingShutterMs);
  sensorTiming.depthTimeOffsetMs =
      r.readDouble("depth_time_offset_ms", sensorTiming.depthTimeOffsetMs);
  estimateFrameVelocity = r.readBool("estimate_frame_velocity", estimateFrameVelocity);
  velocityPriorSigmaMetres = r.readDouble("velocity_prior_sigma_m", velocityPriorSigmaMetres);
  velocityPriorSigmaDegrees = r.readDouble("velocity_prior_sigma_deg", velocityPriorSigmaDegrees);
  adaptiveVelocityPrior = r.readBool("velocity_prior_adaptive", adaptiveVelocityPrior);
  velocityPriorMinSigmaMetres =
      r.readDouble("velocity_prior_min_sigma_m", velocityPriorMinSigmaMetres);
  velocityPriorMinSigmaDegrees =
      r.readDouble("velocity_prior_min_sigma_deg", velocityPriorMinSigmaDegrees);
  depthOnly.minAssociatedFraction =
      r.readDouble("depth_only_min_overlap", depthOnly.minAssociatedFraction);
  depthOnly.maxRmsResidual = r.readDouble("depth_only_max_residual", depthOnly.maxRmsResidual);
  depthOnly.minConstraint = r.readDouble("depth_only_min_constraint", depthOnly.minConstraint);

  pool.index = poolIndexTypeFromString(r.readString("pool_index", toString(pool.index)));
  pool.kdTrees = r.readInt("kdtree_trees", pool.kdTrees);
  pool.checks = r.readInt("kdtree_checks", pool.checks);
  pool.bruteForceBelow = r.readInt("pool_brute_force_below", pool.bruteForceBelow);
  pool.neighbours = r.readInt("knn_neighbours", pool.neighbours);
  pool.searchThreads = r.readInt("search_threads", pool.searchThreads);
  pool.frustumFilter = r.readBool("pool_frustum_filter", pool.frustumFilter);
  pool.frustumFar = r.readDouble("pool_frustum_far", pool.frustumFar);
  pool.frustumMargin = r.readDouble("pool_frustum_margin", pool.frustumMargin);
  pool.seed = static_cast<uint32_t>(r.readInt("kdtree_seed", static_cast<int>(pool.seed)));

  ransac.inlierThreshold = r.readDouble("ransac_threshold", ransac.inlierThreshold);
  ransac.depthCoefficient = r.readDouble("ransac_depth_coefficient", ransac.depthCoefficient);
  ransac.confidence = r.readDouble("ransac_confidence", ransac.confidence);
  ransac.maxIterations = r.readInt("ransac_max_iterations", ransac.maxIterations);
  ransac.minInliers = r.readInt("min_inliers", ransac.minInliers);
  ransac.seed = static_cast<uint32_t>(r.readInt("ransac_seed", static_cast<int>(ransac.seed)));

  keyframes.gridCols = r.readInt("grid_cols", keyframes.gridCols);
  keyframes.gridRows = r.readInt("grid_rows", keyframes.gridRows);
  keyframes.minInliersPerCell = r.readInt("cell_min_inliers", keyframes.minInliersPerCell);
  keyframes.minOverlap = r.readDouble("keyframe_overlap", keyframes.minOverlap);
  keyframes.onlyTexturedCells = r.readBool("only_textured_cells", keyframes.onlyTexturedCells);
  keyframes.texturedCellFeatures =
      r.readInt("textured_cell_features", keyframes.texturedCellFeatures);
  r.rejectUnknownKeys();

  auto require = [&](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument("[" + section + "] " + what);
  };
  require(windowSize > 0, "window_size must be > 0");
  require(windowShift >= 0, "window_shift must be >= 0");
  require(windowShiftAngle >= 0 && windowShiftAngle <= 180,
          "window_shift_angle must be in [0, 180]");
  require(poolHandoverFrames >= 0, "pool_handover_frames must be >= 0");
  require(poolHandoverFeaturesPerFrame > 0, "pool_handover_features_per_frame must be > 0");
  require(ratioThreshold > 0 && ratioThreshold <= 1, "ratio_threshold must be in (0, 1]");
  require(pool.neighbours >= 2, "knn_neighbours must be >= 2");
  require(keypointScaleSigma >= 0 && std::isfinite(keypointScaleSigma),
          "keypoint_scale_sigma must be a finite number >= 0");
  require(depthAlignmentWeight >= 0, "depth_alignment_weight must be >= 0");
  require(depthAlignmentStride >= 1, "depth_alignment_stride must be >= 1");
  require(depthEdgeMaxMatches >= 1, "depth_edge_max_matches must be >= 1");
  require(depthOnly.minAssociatedFraction >= 0 && depthOnly.minAssociatedFraction <= 1,
          "depth_only_min_overlap must be in [0, 1]");
  require(depthOnly.maxRmsResidual > 0, "depth_only_max_residual must be > 0");
  require(depthOnly.minConstraint >= 0, "depth_only_min_constraint must be >= 0");
  require(pool.searchThreads >= 1, "search_threads must be >= 1");
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
  require(pool.bruteForceBelow >= 0, "pool_brute_force_below must be >= 0");
  require(ransac.inlierThreshold > 0, "ransac_threshold must be > 0");
  require(ransac.confidence > 0 && ransac.confidence < 1, "ransac_confidence must be in (0, 1)");
  require(ransac.maxIterations >= 1, "ransac_max_iterations must be >= 1");
  require(ransac.minInliers >= 3, "min_inliers must be >= 3");
  require(keyframes.gridCols >= 1 && keyframes.gridRows >= 1, "grid_cols, grid_rows must be >= 1");
  require(keyframes.minOverlap >= 0 && keyframes.minOverlap <= 1,
          "keyframe_overlap must be in [0, 1]");
}

void TrackerOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                      const std::string& s) const {
  cfg.write(s, "window_size", windowSize);
  cfg.write(s, "window_shift", windowShift);
  cfg.write(s, "window_shift_angle", windowShiftAngle);
  cfg.write(s, "pool_in_background", poolInBackground);
  cfg.write(s, "pool_handover_frames", poolHandoverFrames);
  cfg.write(s, "pool_handover_features_per_frame", poolHandoverFeaturesPerFrame);
  cfg.write(s, "ratio_threshold", ratioThreshold);
  cfg.write(s, "loop_hop_threshold", loopHopThreshold);
  cfg.write(s, "loop_min_inliers", loopMinInliers);
  cfg.write(s, "edge_min_matches", edgeMinMatches);
  cfg.write(s, "min_features", minFeatures);
  cfg.write(s, "relocalize_after", relocalizeAfter);
  cfg.write(s, "relocalize_min_inliers", relocalizeMinInliers);
  cfg.write(s, "max_translation_jump", maxTranslationJump);
  cfg.write(s, "keep_keyframe_images", keepKeyframeImages);
  cfg.write(s, "weighted_refit", weightedRefit);
  cfg.write(s, "edge_information", toString(edgeInformation));
  cfg.write(s, "keypoint_scale_sigma", keypointScaleSigma);
  cfg.write(s, "anisotropic_refinement", anisotropicRefinement);
  cfg.write(s, "depth_alignment_weight", depthAlignmentWeight);
  cfg.write(s, "depth_alignment_stride", depthAlignmentStride);
  cfg.write(s, "depth_alignment_max_distance", depthAlignmentMaxDistance);
  cfg.write(s, "depth_alignment_max_depth", depthAlignmentMaxDepth);
  cfg.write(s, "depth_alignment_central_normals", depthAlignmentCentralNormals);
  cfg.write(s, "depth_edges", depthEdges);
  cfg.write(s, "depth_edge_max_matches", depthEdgeMaxMatches);
  cfg.write(s, "depth_edge_weight", depthEdgeWeight);
  cfg.write(s, "depth_only_fallback", depthOnlyFallback);
  cfg.write(s, "estimate_keypoint_noise", noiseEstimation.enabled);
  cfg.write(s, "estimate_rolling_shutter", rollingShutterEstimation.enabled);
  cfg.write(s, "rolling_shutter_ms", sensorTiming.rollingShutterMs);
  cfg.write(s, "depth_time_offset_ms", sensorTiming.depthTimeOffsetMs);
  cfg.write(s, "estimate_frame_velocity", estimateFrameVelocity);
  cfg.write(s, "velocity_prior_sigma_m", velocityPriorSigmaMetres);
  cfg.write(s, "velocity_prior_sigma_deg", velocityPriorSigmaDegrees);
  cfg.write(s, "velocity_prior_adaptive", adaptiveVelocityPrior);
  cfg.write(s, "velocity_prior_min_sigma_m", velocityPriorMinSigmaMetres);
  cfg.write(s, "velocity_prior_min_sigma_deg", velocityPriorMinSigmaDegrees);
  cfg.write(s, "depth_only_min_overlap", depthOnly.minAssociatedFraction);
  cfg.write(s, "depth_only_max_residual", depthOnly.maxRmsResidual);
  cfg.write(s, "depth_only_min_constraint", depthOnly.minConstraint);
  cfg.write(s, "pool_index", toString(pool.index));
  cfg.write(s, "kdtree_trees", pool.kdTrees);
  cfg.write(s, "kdtree_checks", pool.checks);
  cfg.write(s, "pool_brute_force_below", pool.bruteForceBelow);
  cfg.write(s, "knn_neighbours", pool.neighbours);
  cfg.write(s, "search_threads", pool.searchThreads);
  cfg.write(s, "pool_frustum_filter", pool.frustumFilter);
  cfg.write(s, "pool_frustum_far", pool.frustumFar);
  cfg.write(s, "pool_frustum_margin", pool.frustumMargin);
  cfg.write(s, "kdtree_seed", static_cast<int>(pool.seed));
  cfg.write(s, "ransac_threshold", ransac.inlierThreshold);
  cfg.write(s, "ransac_depth_coefficient", ransac.depthCoefficient);
  cfg.write(s, "ransac_confidence", ransac.confidence);
  cfg.write(s, "ransac_max_iterations", ransac.maxIterations);
  cfg.write(s, "min_inliers", ransac.minInliers);
  cfg.write(s, "ransac_seed", static_cast<int>(ransac.seed));
  cfg.write(s, "grid_cols", keyframes.gridCols);
  cfg.write(s, "grid_rows", keyframes.gridRows);
  cfg.write(s, "cell_min_inliers", keyframes.minInliersPerCell);
  cfg.write(s, "keyframe_overlap", keyframes.minOverlap);
  cfg.write(s, "only_textured_cells", keyframes.onlyTexturedCells);
  cfg.write(s, "textured_cell_features", keyframes.texturedCellFeatures);
}

}  // namespace slamdunk
