// Offscreen rendering of a small synthetic map: the PNG has the requested size, shows the cloud
// (its colours, framed inside the picture), and the .3Dscene reads back. No dataset needed.

#include <slamdunk/dense/DenseReconstruction.h>
#include <slamdunk/dense/MapRenderer.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

struct Room {
  DenseCloud cloud;
  std::vector<Pose> keyframes;
};

/// A 2 m x 1.5 m room corner in the optical world frame (y down): a red floor (y = +1), a green
/// back wall (z = 3) and a blue side wall (x = -1), plus three keyframes looking at it.
Room makeRoom() {
  Room room;
  DenseCloud& cloud = room.cloud;
  for (float a = -1; a <= 1; a += 0.02f)
    for (float b = 0; b <= 1.5f; b += 0.02f) {
      cloud.add({a, 1.0f, 1.5f + b}, {220, 40, 40});                        // floor
      cloud.add({a, 1.0f - b, 3.0f}, {40, 200, 40});                        // back wall
      cloud.add({-1.0f, 1.0f - b, 1.5f + (a + 1) * 0.75f}, {50, 60, 230});  // side wall
    }
  for (int i = 0; i < 3; ++i) {
    Pose T = Pose::Identity();
    T.translation() = Eigen::Vector3d(0.3 * i, 0, 0);
    room.keyframes.push_back(T);
  }
  return room;
}

struct PixelStats {
  double nonBackground = 0;  ///< fraction
  double borderNonBackground = 0;
  int reddish = 0, greenish = 0, bluish = 0;
};

PixelStats analyse(const cv::Mat& bgr) {
  const cv::Vec3b bg = bgr.at<cv::Vec3b>(0, 0);
  PixelStats s;
  int border = 0, borderHits = 0, hits = 0;
  for (int v = 0; v < bgr.rows; ++v)
    for (int u = 0; u < bgr.cols; ++u) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(v, u);
      const bool isBg = cv::norm(cv::Vec3i(p) - cv::Vec3i(bg), cv::NORM_L1) <= 6;
      const bool onBorder = u < 2 || v < 2 || u >= bgr.cols - 2 || v >= bgr.rows - 2;
      border += onBorder;
      if (isBg) continue;
      ++hits;
      borderHits += onBorder;
      const int b = p[0], g = p[1], r = p[2];
      s.reddish += r > 150 && g < 100 && b < 100;
      s.greenish += g > 130 && r < 100 && b < 100;
      s.bluish += b > 150 && r < 110 && g < 110;
    }
  s.nonBackground = double(hits) / double(bgr.total());
  s.borderNonBackground = double(borderHits) / border;
  return s;
}

}  // namespace

TEST(MapRenderer, RendersTheCloudFramedAndInColour) {
  const std::string dir = test::scratchDir("MapRenderer_Renders");
  const auto [cloud, keyframes] = makeRoom();

  RenderOptions options;
  options.width = 400;
  options.height = 300;
  MapRenderer renderer(options);
  renderer.setCloud(cloud);
  renderer.setKeyframePoses(keyframes);
  Trajectory traj;
  for (const auto& T : keyframes) traj.push_back({0.0, T});
  renderer.setTrajectory(traj);

  const auto t0 = std::chrono::steady_clock::now();
  const auto scene = renderer.buildScene();
  const std::string png = dir + "/room.png";
  renderer.renderPng(*scene, png);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "[ render ] " << cloud.size() << " points, 400x300: " << ms << " ms\n";

  const cv::Mat img = cv::imread(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty()) << "PNG not written or unreadable: " << png;
  EXPECT_EQ(img.cols, 400);
  EXPECT_EQ(img.rows, 300);
  const PixelStats s = analyse(img);
  std::cout << "[ render ] non-background " << s.nonBackground * 100 << "%, border "
            << s.borderNonBackground * 100 << "%, red/green/blue pixels " << s.reddish << "/"
            << s.greenish << "/" << s.bluish << "\n";
  EXPECT_GT(s.nonBackground, 0.10) << "the map covers too little of the picture";
  EXPECT_LT(s.borderNonBackground, 0.02) << "the automatic framing cuts the map off";
  EXPECT_GT(s.reddish, 200);
  EXPECT_GT(s.greenish, 200);
  EXPECT_GT(s.bluish, 200);
  // No temporary file left beside the output.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(MapRenderer, ViewIsZUpAndFitsTheMap) {
  const auto [cloud, keyframes] = makeRoom();
  MapRenderer renderer;
  renderer.setCloud(cloud);
  const RenderView v = renderer.view();
  // Optical y (down) becomes display -z: the floor (y = +1) is the lowest part of the box.
  EXPECT_NEAR(v.boxMin.z(), -1.0, 0.05);
  EXPECT_NEAR(v.boxMax.z(), 0.5, 0.05);
  // Optical z (forward, 1.5..3 m) becomes display x.
  EXPECT_NEAR(v.boxMin.x(), 1.5, 0.05);
  EXPECT_NEAR(v.boxMax.x(), 3.0, 0.05);
  const double radius = 0.5 * (v.boxMax - v.boxMin).norm();
  EXPECT_GT(v.distance, radius);
  EXPECT_LT(v.distance, 6 * radius);

  RenderOptions fixed;
  fixed.distance = 7.5;
  fixed.azimuthDeg = 10;
  MapRenderer r2(fixed);
  r2.setCloud(cloud);
  EXPECT_DOUBLE_EQ(r2.view().distance, 7.5);
  EXPECT_DOUBLE_EQ(r2.view().azimuthDeg, 10);
}

TEST(MapRenderer, LevelsTheViewWithPitchedPanningCameras) {
  // Cameras pitched 30 degrees down and panning +-40 degrees: the first camera's up is tilted,
  // the true up is world -y (optical y points down), which the cameras' right axes all avoid.
  std::vector<Pose> cameras;
  for (double yawDeg : {0.0, -40.0, 40.0, 20.0}) {
    Pose T = Pose::Identity();
    T.linear() = (Eigen::AngleAxisd(yawDeg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(-30 * M_PI / 180, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    cameras.push_back(T);
  }
  MapRenderer renderer;
  renderer.setKeyframePoses(cameras);
  const Pose D = renderer.worldToDisplay();
  EXPECT_TRUE(D.linear().row(2).transpose().isApprox(Eigen::Vector3d(0, -1, 0), 1e-9))
      << D.linear();
  EXPECT_NEAR(D.linear().determinant(), 1.0, 1e-9);
  // x is the first camera's view direction laid flat: optical z.
  EXPECT_TRUE(D.linear().row(0).transpose().isApprox(Eigen::Vector3d(0, 0, 1), 1e-9));

  // A single camera cannot tell: its own up is used, and switching levelling off gives the
  // fixed optical-to-sensor rotation.
  MapRenderer one;
  one.setKeyframePoses({cameras.front()});
  EXPECT_TRUE(one.worldToDisplay().linear().row(2).transpose().isApprox(
      -cameras.front().linear().col(1), 1e-9));
  RenderOptions fixed;
  fixed.levelWithCameras = false;
  MapRenderer off(fixed);
  off.setKeyframePoses(cameras);
  EXPECT_TRUE(off.worldToDisplay().isApprox(opticalInSensor()));
}

TEST(MapRenderer, SceneFileReadsBack) {
  const std::string dir = test::scratchDir("MapRenderer_Scene");
  const auto [cloud, keyframes] = makeRoom();
  MapRenderer renderer;
  renderer.setCloud(cloud);
  renderer.setKeyframePoses(keyframes);
  const std::string path = dir + "/room.3Dscene";
  MapRenderer::saveScene(*renderer.buildScene(), path);

  const auto scene = MapRenderer::loadScene(path);
  ASSERT_TRUE(scene);
  auto map =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(scene->getByName("slamdunk_map"));
  ASSERT_TRUE(map) << "the map group is missing from the saved scene";
  auto pts =
      std::dynamic_pointer_cast<mrpt::opengl::CPointCloudColoured>(map->getByName("dense_cloud"));
  ASSERT_TRUE(pts);
  EXPECT_EQ(pts->size(), cloud.size());
  auto frustums =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(map->getByName("keyframes"));
  ASSERT_TRUE(frustums);
  EXPECT_EQ(std::distance(frustums->begin(), frustums->end()), 3);
}

TEST(MapRenderer, BadInputIsAClearError) {
  RenderOptions bad;
  bad.width = 0;
  EXPECT_THROW(MapRenderer{bad}, std::invalid_argument);
  bad = {};
  bad.elevationDeg = 120;
  EXPECT_THROW(MapRenderer{bad}, std::invalid_argument);

  const std::string dir = test::scratchDir("MapRenderer_Bad");
  EXPECT_THROW(MapRenderer::loadScene(dir + "/missing.3Dscene"), std::runtime_error);
  std::ofstream(dir + "/garbage.3Dscene") << "not a scene at all";
  EXPECT_THROW(MapRenderer::loadScene(dir + "/garbage.3Dscene"), std::runtime_error);
  // An unwritable destination throws and leaves nothing behind.
  MapRenderer r;
  EXPECT_THROW(r.renderPng(*r.buildScene(), dir + "/no/such/folder/x.png"), std::runtime_error);
}

TEST(DenseCloud, VoxelFilterMergesPointsAndAveragesColours) {
  DenseCloud c;
  // Four points in one 10 cm voxel, one in another.
  c.add({0.01f, 0.01f, 0.01f}, {0, 0, 0});
  c.add({0.02f, 0.03f, 0.04f}, {100, 0, 0});
  c.add({0.05f, 0.05f, 0.05f}, {200, 0, 0});
  c.add({0.09f, 0.09f, 0.09f}, {100, 0, 0});
  c.add({0.55f, 0.05f, 0.05f}, {0, 255, 0});
  const DenseCloud f = voxelFilter(c, 0.1);
  ASSERT_EQ(f.size(), 2u);
  const size_t a = f.points[0].x() < 0.3f ? 0 : 1;
  EXPECT_NEAR(f.points[a].x(), 0.0425, 1e-4);
  EXPECT_NEAR(f.colours[a][0], 100, 1);
  EXPECT_EQ(f.colours[1 - a][1], 255);
}

TEST(DenseCloud, BackProjectionUsesPoseIntrinsicsAndDepthRange) {
  Keyframe kf;
  kf.intrinsics = CameraIntrinsics{};  // 640x480, f 525
  kf.depth = cv::Mat(480, 640, CV_32F, cv::Scalar(2.0f));
  kf.depth.at<float>(0, 0) = 0.1f;                                 // too close: dropped
  kf.colour = cv::Mat(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));  // BGR
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(1, 2, 3);
  DenseOptions o;
  o.pixelStride = 4;
  o.voxelSize = 0;
  const DenseCloud c = backProjectKeyframe(kf, T, o);
  EXPECT_EQ(c.size(), size_t(160 * 120 - 1));
  for (const auto& p : c.points) ASSERT_NEAR(p.z(), 5.0, 1e-5);
  const DenseCloud::Rgb rgb{30, 20, 10};
  EXPECT_EQ(c.colours.front(), rgb);
  // Pixel (320, 240) is near the principal point: straight ahead of the camera.
  const Eigen::Vector3d centre = T * kf.intrinsics.backProject(320, 240, 2.0);
  bool found = false;
  for (const auto& p : c.points) found |= (p.cast<double>() - centre).norm() < 1e-4;
  EXPECT_TRUE(found);

  o.pixelStride = 0;
  EXPECT_THROW(backProjectKeyframe(kf, T, o), std::invalid_argument);
}
