#include <slamdunk/mrpt_map/CameraFrustum.h>

#include <mrpt/poses/CPose3D.h>

#include <cmath>

namespace slamdunk {

void FrustumShape::setFieldOfView(const CameraIntrinsics& K) {
  horzFovDeg = float(2.0 * std::atan2(0.5 * K.width, K.fx) * 180.0 / M_PI);
  vertFovDeg = float(2.0 * std::atan2(0.5 * K.height, K.fy) * 180.0 / M_PI);
}

mrpt::opengl::CFrustum::Ptr makeCameraFrustum(const FrustumShape& shape,
                                              const Pose& T_world_optical) {
  auto f = mrpt::opengl::CFrustum::Create(shape.nearDistance, shape.farDistance, shape.horzFovDeg,
                                          shape.vertFovDeg, shape.lineWidth, true, false);
  f->setColor_u8(shape.colour);
  // The MRPT sensor frame looks along +X, as CFrustum does.
  f->setPose(toCPose3D(opticalToSensorPose(T_world_optical)));
  return f;
}

}  // namespace slamdunk
