#include <slamdunk/mrpt_map/CameraFrustum.h>

#include <gtest/gtest.h>
#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <vector>

using namespace slamdunk;

namespace {

/// The frustum's apex and far-plane corners in world coordinates, from what CFrustum draws: in
/// its own frame it looks along +X, its far plane at x = far.
std::vector<Eigen::Vector3d> drawnCorners(const mrpt::opengl::CFrustum& f) {
  const double far = f.getFarPlaneDistance();
  const double h = std::tan(f.getHorzFOV() / 2 * M_PI / 180) * far;
  const double v = std::tan(f.getVertFOV() / 2 * M_PI / 180) * far;
  const mrpt::poses::CPose3D& pose = f.getPoseRef();
  std::vector<Eigen::Vector3d> out;
  for (const auto& [x, y, z] : std::vector<std::array<double, 3>>{
           {0, 0, 0}, {far, h, v}, {far, -h, v}, {far, h, -v}, {far, -h, -v}}) {
    const mrpt::math::TPoint3D w = pose.composePoint(mrpt::math::TPoint3D(x, y, z));
    out.emplace_back(w.x, w.y, w.z);
  }
  return out;
}

bool contains(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& p) {
  for (const auto& q : points)
    if ((q - p).norm() < 1e-5) return true;
  return false;
}

}  // namespace

TEST(CameraFrustum, TheFieldOfViewOfACamera) {
  CameraIntrinsics K;  // 640x480, f = 525
  FrustumShape shape;
  shape.setFieldOfView(K);
  EXPECT_NEAR(shape.horzFovDeg, 62.7266, 1e-3);  // 2 atan(320 / 525)
  EXPECT_NEAR(shape.vertFovDeg, 49.1343, 1e-3);  // 2 atan(240 / 525)
}

TEST(CameraFrustum, ItsCornersAreWhereTheCameraLooks) {
  // A camera 1 m along world x, turned 90 degrees about the optical y axis (down): it looks
  // along world +x.
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, 0, 0);
  FrustumShape shape;
  shape.farDistance = 2.0f;
  shape.horzFovDeg = 90.0f;       // far-plane half-width 2 m
  shape.vertFovDeg = 53.130102f;  // far-plane half-height 1 m (2 atan(1/2))
  shape.colour = mrpt::img::TColor(255, 170, 40);
  const auto f = makeCameraFrustum(shape, T);
  EXPECT_EQ(f->getColor_u8(), mrpt::img::TColor(255, 170, 40));
  const auto corners = drawnCorners(*f);
  // In the optical frame the far plane is at z = 2, x = +-2, y = +-1; in the world, 2 m ahead
  // along +x, its sides 2 m along -z and +z, 1 m up and down along y.
  EXPECT_TRUE(contains(corners, Eigen::Vector3d(1, 0, 0))) << "apex at the camera centre";
  for (const auto& optical : {Eigen::Vector3d(2, 1, 2), Eigen::Vector3d(-2, 1, 2),
                              Eigen::Vector3d(2, -1, 2), Eigen::Vector3d(-2, -1, 2)}) {
    const Eigen::Vector3d world = T * optical;
    EXPECT_TRUE(contains(corners, world)) << world.transpose();
  }
  EXPECT_TRUE(contains(corners, Eigen::Vector3d(3, 1, -2)));  // one of them, written out
}
