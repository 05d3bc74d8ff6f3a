#pragma once
// Detects keypoints on the grey image, keeps those with valid depth (the strongest, up to a
// cap), describes them and back-projects them (undistorted keypoint, depth at its pixel).

#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/EnumNames.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/features/FeatureSet.h>

#include <mrpt/config/CLoadableOptions.h>
#include <opencv2/features2d.hpp>

#include <memory>
#include <string>

namespace slamdunk {

enum class FeatureType { SURF64, SURF128, SIFT, ORB };

SLAMDUNK_ENUM_NAMES(FeatureType, {{FeatureType::SURF64, "SURF64"},
                                  {FeatureType::SURF64, "SURF-64"},
                                  {FeatureType::SURF64, "SURF"},
                                  {FeatureType::SURF128, "SURF128"},
                                  {FeatureType::SURF128, "SURF-128"},
                                  {FeatureType::SIFT, "SIFT"},
                                  {FeatureType::ORB, "ORB"}});

struct FeatureOptions : public mrpt::config::CLoadableOptions {
  FeatureType type = FeatureType::SURF64;
  int maxFeatures = 500;              ///< cap on features with valid depth per frame
  double surfHessianThreshold = 500;  ///< SURF detector threshold
  bool surfUpright = true;            ///< skip SURF orientation (hand-held cameras stay level)
  /// Upright SURF describes a rolled view's features rolled with it. A frame rolled by more
  /// than this (degrees) against the keyframe it is tracked from is described with its windows
  /// turned by that roll, as that keyframe described them. 0: never (the paper). Upright SURF
  /// only: oriented SURF, SIFT and ORB turn each window by its keypoint's own orientation.
  double surfRollLimitDeg = 10;
  int surfOctaves = 4;
  int orbDetectFeatures = 1000;  ///< ORB detects this many before the depth filter
  int orbFastThreshold = 20;
  int siftDetectFeatures = 0;  ///< 0 = all
  double minDepth = 0.2;       ///< metres: nearer points are sensor noise
  double maxDepth = 6.0;       ///< metres: farther Kinect depth is too noisy to use
  /// Reject a keypoint when depths within `depthCheckRadius` pixels differ from its own by more
  /// than this fraction: on a depth edge a pixel of misregistration picks the wrong surface.
  double maxDepthDiscontinuity = 0.05;
  int depthCheckRadius = 2;  ///< 0 disables the check
  /// How precisely a feature is measured: its keypoint's pixel and the depth read there. Used
  /// wherever features are weighed (pose refinement, graph edges, bundle adjustment).
  DepthNoiseModel noise;

  /// Its INI keys (section [features]), listed once for loading and saving.
  template <class Self, class Keys>
  static void forEachKey(Self& o, Keys& k) {
    k("type", o.type);
    k("max_features", o.maxFeatures);
    k("surf_hessian_threshold", o.surfHessianThreshold);
    k("surf_upright", o.surfUpright);
    k("surf_octaves", o.surfOctaves);
    k("surf_roll_limit_deg", o.surfRollLimitDeg);
    k("orb_detect_features", o.orbDetectFeatures);
    k("orb_fast_threshold", o.orbFastThreshold);
    k("sift_detect_features", o.siftDetectFeatures);
    k("min_depth", o.minDepth);
    k("max_depth", o.maxDepth);
    k("max_depth_discontinuity", o.maxDepthDiscontinuity);
    k("depth_check_radius", o.depthCheckRadius);
    k("keypoint_pixel_sigma", o.noise.pixelSigma);
    k("keypoint_depth_sigma", o.noise.depthSigmaQuadratic);
  }

  void loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                          const std::string& section) override;
  void saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                        const std::string& section) const override;
};

class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureOptions& options);
  ~FeatureExtractor();

  /// turnDegrees: the frame's descriptor windows turned by it, as describeTurned() turns them
  /// (0: as the options say).
  FeatureSet extract(const RgbdFrame& frame, double turnDegrees = 0) const;
  const FeatureOptions& options() const { return options_; }
  /// cv::NORM_L2 or cv::NORM_HAMMING
  int descriptorNorm() const;
  /// Upright SURF, whose windows a rolled view can be described turned in
  /// (FeatureOptions::surfRollLimitDeg above 0).
  bool turnsDescriptors() const;
  /// Describes the features again with every upright SURF window turned by turnDegrees (image
  /// coordinates, y down; 0: upright). False, leaving them as they are, when windows cannot be
  /// turned (turnsDescriptors()).
  bool describeTurned(const RgbdFrame& frame, FeatureSet& features, double turnDegrees) const;
  /// Whether the features' windows are turned by turnDegrees (0: upright, or as the options say
  /// where windows cannot be turned).
  bool describedWith(const FeatureSet& features, double turnDegrees) const;

 private:
  FeatureOptions options_;
  cv::Ptr<cv::Feature2D> detector_;

  /// Descriptors of `keypoints` (which it may drop or reorder, as cv::Feature2D::compute).
  cv::Mat describe(const cv::Mat& grey, std::vector<cv::KeyPoint>& keypoints,
                   double turnDegrees) const;
};

}  // namespace slamdunk
