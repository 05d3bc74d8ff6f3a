#pragma once
// Offscreen RGB-D rendering of an MRPT scene through an exact pinhole camera (MRPT's CFBORender
// with an EGL context; Mesa's software renderer when there is no GPU or display).

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/core/Pose.h>

#include <opencv2/core/mat.hpp>

#include <memory>

namespace mrpt::opengl {
class COpenGLScene;
}

namespace slamdunk {

class SyntheticRenderer {
 public:
  /// Clip planes: nothing nearer than kNearClip is drawn (real RGB-D sensors see nothing closer
  /// than about 0.5 m either), nothing beyond kFarClip (depth 0 there). A near plane well away
  /// from zero keeps the depth buffer's resolution below 0.3 mm up to 4 m.
  static constexpr double kNearClip = 0.4;
  static constexpr double kFarClip = 12.0;

  /// `supersampling` (odd: 1, 3, 5) renders colour at that many times the resolution and
  /// averages blocks (anti-aliasing); depth is taken at the centre sample of each block, which
  /// is exactly the pixel centre, so depth stays the exact z of the surface seen there.
  /// Throws std::invalid_argument for lens distortion, a bad size or an even factor, and
  /// std::runtime_error when no EGL/OpenGL context can be created.
  explicit SyntheticRenderer(const CameraIntrinsics& intrinsics, int supersampling = 3);
  ~SyntheticRenderer();
  SyntheticRenderer(const SyntheticRenderer&) = delete;
  SyntheticRenderer& operator=(const SyntheticRenderer&) = delete;

  /// Renders `scene` seen by a camera whose optical frame has world pose T_w_opt.
  /// A scene keeps the OpenGL objects (textures, buffers) of the context that first drew it:
  /// render a given scene with one renderer only, and from the thread that created the renderer.
  /// bgr: CV_8UC3 colour; depth: CV_32F z-depth in metres along the optical axis (not the
  /// distance along the ray), 0 where no surface lies between the clip planes.
  void render(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt, cv::Mat& bgr, cv::Mat& depth);
  /// The colour of render() alone, byte for byte, without reading the depth buffer back.
  void renderColour(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt, cv::Mat& bgr);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  int supersampling() const { return supersampling_; }

 private:
  void placeCamera(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt);
  void copyColour(cv::Mat& bgr) const;  ///< the last render's colour, at the image's size

  struct Impl;
  std::unique_ptr<Impl> impl_;
  CameraIntrinsics intrinsics_;
  int supersampling_;
};

}  // namespace slamdunk
