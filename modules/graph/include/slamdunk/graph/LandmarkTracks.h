#pragma once
// Landmarks for the bundle adjustment: a feature matched from keyframe to keyframe is one point
// of the scene seen several times. Following the edges' feature matches (union-find over
// (keyframe, feature)) gathers each point's observations, so that the optimization estimates
// the point once from all of them instead of trusting each pair's depths separately.

#include <slamdunk/graph/KeyframeGraph.h>

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace slamdunk {

/// One keyframe's measurement of a landmark: its feature's 3D point in that keyframe's frame
/// (the keypoint's undistorted ray, scaled to the depth read there).
struct LandmarkObservation {
  KeyframeId keyframe = 0;
  uint32_t feature = 0;
  Eigen::Vector3d point;
};

struct Landmark {
  std::vector<LandmarkObservation> observations;  ///< at least two, one per keyframe
};

struct LandmarkTracks {
  std::vector<Landmark> landmarks;
  /// Matches that do not join two features (dense depth): (edge index, match index).
  std::vector<std::pair<size_t, size_t>> pointMatches;
  /// Tracks dropped because they reach one keyframe through two different features: a wrong
  /// match joined two points of the scene.
  size_t inconsistentTracks = 0;
};

/// Gathers the landmarks of a set of edges. Deterministic: landmarks come in the order of their
/// first observation in the edges, observations in the order they were reached.
LandmarkTracks buildLandmarkTracks(const std::vector<KeyframeEdge>& edges);

}  // namespace slamdunk
