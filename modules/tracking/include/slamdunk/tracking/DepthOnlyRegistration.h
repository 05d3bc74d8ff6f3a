#pragma once
// Registration by depth alone, for frames whose features do not register (textureless scenes:
// a plain box on a plain floor). Beyond the paper, which loses such frames. Coarse-to-fine
// point-to-plane alignment of the frame's depth with a reference keyframe's depth, from a
// predicted pose; accepted only when the surfaces overlap enough, fit closely and constrain
// all six degrees of freedom (a single wall or floor does not).

#include <slamdunk/tracking/PoseRefinement.h>

#include <string>
#include <vector>

namespace slamdunk {

struct DepthOnlyOptions {
  /// Association gates of the successive levels, metres: wide first to pull in a rough
  /// prediction, then the dense term's own gate.
  std::vector<double> maxDistances = {0.20, 0.10, 0.05};
  int iterationsPerLevel = 10;
  double minAssociatedFraction = 0.5;  ///< of the frame's depth samples on the reference's
  double maxRmsResidual = 0.015;       ///< metres, point-to-plane, at the final pose
  /// Share of the surfaces that must face the geometry's weakest direction: below it the pose
  /// can slide along them (a corridor's walls, floor and ceiling; a box face-on on the floor).
  double minConstraint = 0.01;
  /// The reference normals are fitted to windows of ±normalRadius pixels of its depth
  /// (fitPlaneNormals) unless the term brings its own.
  int normalRadius = 2;

  /// Its INI keys (in [tracker]), listed once for IniSectionReader and IniSectionWriter.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("depth_only_min_overlap", o.minAssociatedFraction);
    k("depth_only_max_residual", o.maxRmsResidual);
    k("depth_only_min_constraint", o.minConstraint);
  }
};

struct DepthOnlyResult {
  bool success = false;
  Pose pose = Pose::Identity();
  double associatedFraction = 0;  ///< of the frame's depth samples: the overlap estimate
  double rmsResidual = 0;
  double constraint = 0;  ///< weakest direction, see DepthOnlyOptions::minConstraint
  std::string failure;    ///< why it was rejected
};

/// Aligns term.framePoints with term.referenceDepth starting from `predicted` (world <- camera).
/// term.maxDistance is overwritten per level.
DepthOnlyResult registerByDepthOnly(const Pose& predicted, DepthAlignmentTerm term,
                                    const DepthOnlyOptions& options = {});

}  // namespace slamdunk
