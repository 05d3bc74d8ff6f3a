#include <slamdunk/synthetic/SyntheticRenderer.h>

#include <mrpt/img/CImage.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/math/CMatrixDynamic.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <string>

namespace slamdunk {

struct SyntheticRenderer::Impl {
  explicit Impl(unsigned w, unsigned h) : fbo(w, h) {}
  mrpt::opengl::CFBORender fbo;
  mrpt::img::TCamera glCamera;  // pinhole model handed to OpenGL (supersampled, GL pixel centres)
  mrpt::img::CImage rgb;
  mrpt::math::CMatrixFloat depth;
};

SyntheticRenderer::SyntheticRenderer(const CameraIntrinsics& intrinsics, int supersampling)
    : intrinsics_(intrinsics), supersampling_(supersampling) {
  if (intrinsics.hasDistortion())
    throw std::invalid_argument("synthetic renderer: lens distortion is not supported");
  if (intrinsics.width <= 0 || intrinsics.height <= 0 || !(intrinsics.fx > 0) ||
      !(intrinsics.fy > 0))
    throw std::invalid_argument("synthetic renderer: image size and focal lengths must be > 0");
  if (supersampling < 1 || supersampling % 2 == 0 || supersampling > 7)
    throw std::invalid_argument("synthetic renderer: supersampling must be 1, 3, 5 or 7, not " +
                                std::to_string(supersampling));
  const int s = supersampling;
  const unsigned W = unsigned(intrinsics.width * s), H = unsigned(intrinsics.height * s);
  try {
    impl_ = std::make_unique<Impl>(W, H);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("synthetic renderer: cannot create an offscreen OpenGL "
                                         "(EGL) context: ") +
                             e.what());
  }
  // Hi-res pixel j covers low-res coordinate u = (j - (s-1)/2) / s, so its centre sample is at
  // the low-res pixel centre: fx' = s fx, cx' = s cx + (s-1)/2.
  // OpenGL samples a pixel at its centre, window coordinate j + 0.5, while MRPT's pinhole
  // projection maps u' straight to window coordinates: +0.5 makes pixel j see u' = j
  // (measured: without it depth on a slanted plane is off by half a pixel).
  auto& cam = impl_->glCamera;
  cam.ncols = W;
  cam.nrows = H;
  cam.setIntrinsicParamsFromValues(s * intrinsics.fx, s * intrinsics.fy,
                                   s * intrinsics.cx + (s - 1) / 2.0 + 0.5,
                                   s * intrinsics.cy + (s - 1) / 2.0 + 0.5);
}

SyntheticRenderer::~SyntheticRenderer() = default;

void SyntheticRenderer::placeCamera(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt) {
  auto viewport = scene.getViewport();
  viewport->setViewportClipDistances(float(kNearClip), float(kFarClip));
  auto& camera = viewport->getCamera();
  camera.setProjectiveFromPinhole(impl_->glCamera);
  // 6-DOF mode: the camera pose is the optical frame (+z forward, +x right, +y down).
  camera.set6DOFMode(true);
  camera.setPose(toCPose3D(T_w_opt));
  impl_->fbo.setCamera(scene, camera);
}

void SyntheticRenderer::copyColour(cv::Mat& bgr) const {
  const int s = supersampling_;
  const cv::Mat hiRgb = impl_->rgb.asCvMatRef();
  if (s == 1)
    hiRgb.copyTo(bgr);
  else
    cv::resize(hiRgb, bgr, cv::Size(intrinsics_.width, intrinsics_.height), 0, 0,
               cv::INTER_AREA);  // exact block average
}

void SyntheticRenderer::renderColour(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt,
                                     cv::Mat& bgr) {
  placeCamera(scene, T_w_opt);
  impl_->fbo.render_RGB(scene, impl_->rgb);
  copyColour(bgr);
}

void SyntheticRenderer::render(mrpt::opengl::COpenGLScene& scene, const Pose& T_w_opt, cv::Mat& bgr,
                               cv::Mat& depth) {
  placeCamera(scene, T_w_opt);
  impl_->fbo.render_RGBD(scene, impl_->rgb, impl_->depth);
  copyColour(bgr);

  const int s = supersampling_, w = intrinsics_.width, h = intrinsics_.height;
  depth.create(h, w, CV_32F);
  const int off = (s - 1) / 2;
  for (int r = 0; r < h; ++r) {
    float* out = depth.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      const float d = impl_->depth(r * s + off, c * s + off);
      out[c] = (d > 0 && d < kFarClip) ? d : 0.f;
    }
  }
}

}  // namespace slamdunk
