#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumSequence.h>

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/system/datetime.h>

using namespace slamdunk;

namespace {

CameraIntrinsics camera(double f, int w = 160, int h = 120) {
  CameraIntrinsics K;
  K.width = w;
  K.height = h;
  K.fx = K.fy = f;
  K.cx = w / 2.0;
  K.cy = h / 2.0;
  return K;
}

// A slanted plane z = z0 + slope * x (optical frame of the camera that sees it, metres).
struct Plane {
  double z0 = 2.0, slope = 0.5;
  // Depth along a camera's axis at undistorted pixel (u, v), the camera at `centre` (axes
  // parallel to the plane's frame).
  double depthAt(const CameraIntrinsics& K, double u, double v,
                 const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) const {
    const double rx = (u - K.cx) / K.fx;  // ray (rx, ry, 1) * t from the centre
    return (z0 + slope * centre.x() - centre.z()) / (1.0 - slope * rx);
  }
  cv::Mat render(const CameraIntrinsics& K) const {
    cv::Mat d(K.height, K.width, CV_32F);
    for (int r = 0; r < K.height; ++r)
      for (int c = 0; c < K.width; ++c) d.at<float>(r, c) = static_cast<float>(depthAt(K, c, r));
    return d;
  }
};

}  // namespace

TEST(DepthRegistration, SameCameraIsTheIdentity) {
  const CameraIntrinsics K = camera(150);
  const cv::Mat depth = Plane().render(K);
  const cv::Mat out = registerDepthToColour(depth, K, K, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.type(), CV_32FC1);
  EXPECT_EQ(cv::norm(out, depth, cv::NORM_INF), 0.0);
}

TEST(DepthRegistration, ShorterColourFocalLengthReadsTheSurfaceSeenAtTheColourPixel) {
  // A Kinect v1 in miniature: depth camera 585/640 px, colour 525/640 px, same centre.
  const CameraIntrinsics depthK = camera(585.0 / 4), colourK = camera(525.0 / 4);
  const Plane plane;
  const cv::Mat out =
      registerDepthToColour(plane.render(depthK), depthK, colourK, Eigen::Isometry3d::Identity());
  ASSERT_EQ(out.size(), cv::Size(colourK.width, colourK.height));
  int checked = 0;
  for (int r = 10; r < colourK.height - 10; r += 7)
    for (int c = 12; c < colourK.width - 12; c += 5) {
      const float z = out.at<float>(r, c);
      ASSERT_GT(z, 0) << "hole at " << c << "," << r;
      // Within a pixel of the colour ray's intersection (the plane's depth changes by
      // at most slope * z^2 / f per pixel).
      EXPECT_NEAR(z, plane.depthAt(colourK, c, r), 0.02) << c << "," << r;
      ++checked;
    }
  EXPECT_GT(checked, 300);
  // Unregistered, the same pixel reads a surface 10 % farther out along the image: at the
  // right border the depths differ by several centimetres.
  const int c = colourK.width - 12, r = colourK.height / 2;
  EXPECT_GT(std::abs(plane.depthAt(depthK, c, r) - plane.depthAt(colourK, c, r)), 0.05);
  // The colour camera sees wider than the depth camera: its border has no depth.
  EXPECT_EQ(out.at<float>(r, 0), 0.f);
}

// Read at the nearest depth pixel's projection, a colour pixel's depth on this plane would be off
// by up to half a pixel's worth of its slope (7 mm); read where the colour ray lands, it is the
// plane's, with the cameras' centres together or apart.
TEST(DepthRegistration, SlantedSurfaceIsReadWhereTheColourRayLands) {
  const CameraIntrinsics depthK = camera(585.0 / 4), colourK = camera(525.0 / 4);
  const Plane plane;
  const double halfPixelOfSlope = 0.5 * plane.slope * plane.z0 * plane.z0 / depthK.fx;
  ASSERT_GT(halfPixelOfSlope, 0.006);
  for (const double offset : {0.0, 0.02}) {
    const Eigen::Vector3d colourCentre(offset, 0, 0);
    Eigen::Isometry3d depthToColour = Eigen::Isometry3d::Identity();
    depthToColour.translation() = -colourCentre;
    const cv::Mat out = registerDepthToColour(plane.render(depthK), depthK, colourK, depthToColour);
    double worst = 0;
    int checked = 0;
    for (int r = 10; r < colourK.height - 10; ++r)
      for (int c = 12; c < colourK.width - 12; ++c) {
        const float z = out.at<float>(r, c);
        ASSERT_GT(z, 0) << "hole at " << c << "," << r;
        worst = std::max(worst, std::abs(z - plane.depthAt(colourK, c, r, colourCentre)));
        ++checked;
      }
    EXPECT_GT(checked, 8000);
    EXPECT_LT(worst, 5e-4) << "colour camera " << offset << " m from the depth camera";
  }
}

TEST(DepthRegistration, OffsetCameraAndNearestSurfaceWins) {
  // Colour camera 2.5 cm right of the depth camera, same focal length; a box face at 1 m in
  // front of a wall at 3 m.
  const CameraIntrinsics K = camera(150);
  cv::Mat depth(K.height, K.width, CV_16U, cv::Scalar(3000));  // millimetres
  depth(cv::Rect(60, 40, 40, 40)).setTo(1000);
  Eigen::Isometry3d depthToColour = Eigen::Isometry3d::Identity();
  depthToColour.translation() = Eigen::Vector3d(-0.025, 0, 0);
  const cv::Mat out = registerDepthToColour(depth, K, K, depthToColour, 1e-3);
  ASSERT_EQ(out.type(), CV_16UC1);
  // Points shift left in the colour image by f * b / z: 3.75 px at 1 m, 1.25 px at 3 m.
  EXPECT_EQ(out.at<uint16_t>(60, 58), 1000);  // the box's left edge moved left...
  // Right of the box the colour camera sees wall the depth camera could not: no depth there.
  EXPECT_EQ(out.at<uint16_t>(60, 97), 0);
  EXPECT_EQ(out.at<uint16_t>(60, 100), 3000);
  EXPECT_EQ(out.at<uint16_t>(60, 80), 1000);  // the box occludes the wall behind it
  EXPECT_EQ(out.at<uint16_t>(10, 10), 3000);
}

TEST(DepthRegistration, RotatedColourCameraSeesTheSceneTurned) {
  // A calibration whose colour axes are turned 1.5 deg about y against the depth camera's (as a
  // stereo calibration's R gives them), no offset: a box face at 1 m in front of a wall at 3 m.
  const CameraIntrinsics K = camera(150);
  cv::Mat depth(K.height, K.width, CV_16U, cv::Scalar(3000));  // millimetres
  depth(cv::Rect(60, 40, 40, 40)).setTo(1000);
  mrpt::config::CConfigFileMemory cfg(
      "[CAMERA]\nfx = 150\nfy = 150\ncx = 80\ncy = 60\nresolution = [160 120]\n"
      "depth_factor = 1000\n[CAMERA_DEPTH]\nfx = 150\nfy = 150\ncx = 80\ncy = 60\n"
      "resolution = [160 120]\ncolour_rotation = [0.99965732 0 -0.02617695  0 1 0  "
      "0.02617695 0 0.99965732]\n");
  const auto calib = RgbdCameraCalibration::loadFromConfig(cfg);
  const cv::Mat out = registerDepthToColour(depth, K, K, calib.depthToColour(), 1e-3);

  // The depth camera's box edge at column 60 (the pixel's left border, 59.5), seen by the colour
  // camera: its ray turned by -1.5 deg about y lands f tan(atan(-20.5 / 150) - 1.5 deg) from the
  // centre, 3.9 px further left; depths along the turned axis change by < 1 %.
  const double edge = 80 + 150 * std::tan(std::atan((59.5 - 80) / 150) - mrpt::DEG2RAD(1.5));
  EXPECT_NEAR(edge, 55.5, 0.05);
  EXPECT_NEAR(out.at<uint16_t>(60, 57), 1000, 10);  // inside the moved box
  EXPECT_NEAR(out.at<uint16_t>(60, 54), 3000, 30);  // wall left of it
  EXPECT_NEAR(out.at<uint16_t>(60, 93), 1000, 10);  // the box's right edge moved left by as much
  EXPECT_NEAR(out.at<uint16_t>(60, 97), 3000, 30);
  // Axes parallel (the key left out), the box stays where the depth camera saw it.
  const cv::Mat same = registerDepthToColour(depth, K, K, Eigen::Isometry3d::Identity(), 1e-3);
  EXPECT_EQ(same.at<uint16_t>(60, 58), 3000);
  EXPECT_EQ(same.at<uint16_t>(60, 60), 1000);
}

TEST(DepthRegistration, ObservationWithSeparateCamerasIsRegistered) {
  // MRPT's convention: images are pixel-aligned only when relativePoseIntensityWRTDepth is the
  // pure axis change; otherwise RgbdFrame registers depth to colour.
  const CameraIntrinsics depthK = camera(585.0 / 4), colourK = camera(525.0 / 4);
  const Plane plane;
  const cv::Mat depth = plane.render(depthK);
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->timestamp = mrpt::Clock::fromDouble(1.0);
  obs->hasIntensityImage = true;
  obs->intensityImage.resize(colourK.width, colourK.height, mrpt::img::CH_RGB);
  obs->hasRangeImage = true;
  obs->range_is_depth = true;
  obs->rangeImage_setSize(depth.rows, depth.cols);
  for (int r = 0; r < depth.rows; ++r)
    for (int c = 0; c < depth.cols; ++c)
      obs->rangeImage(r, c) = static_cast<uint16_t>(std::lround(depth.at<float>(r, c) * 1000));
  obs->rangeUnits = 1e-3f;
  obs->cameraParams = depthK.toTCamera();
  obs->cameraParamsIntensity = colourK.toTCamera();
  // Colour camera 2 cm to the right of the depth camera (MRPT sensor frame: y points left).
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, -0.02, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  ASSERT_FALSE(obs->doDepthAndIntensityCamerasCoincide());

  const RgbdFrame f = RgbdFrame::fromObservation(*obs);
  const Eigen::Vector3d colourCentre(0.02, 0, 0);
  for (int c : {30, 80, 120}) {
    const int r = 60;
    EXPECT_NEAR(f.depthAt(c, r), plane.depthAt(colourK, c, r, colourCentre), 0.02) << c;
  }

  // The same observation declared pixel-aligned keeps its depth as it is.
  obs->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  const RgbdFrame g = RgbdFrame::fromObservation(*obs);
  EXPECT_NEAR(g.depthAt(120, 60), depth.at<float>(60, 120), 1e-3);
}

TEST(DepthRegistration, CameraFileDeclaresTheDepthCamera) {
  mrpt::config::CConfigFileMemory cfg(
      "[CAMERA]\nfx = 525\nfy = 525\ncx = 320\ncy = 240\ndepth_factor = 1000\n"
      "[CAMERA_DEPTH]\nfx = 585\nfy = 585\ncx = 320\ncy = 240\ncolour_centre = [0.025 0 0]\n");
  const auto c = RgbdCameraCalibration::loadFromConfig(cfg);
  ASSERT_TRUE(c.depthCamera);
  EXPECT_DOUBLE_EQ(c.depthCamera->fx, 585);
  EXPECT_DOUBLE_EQ(c.intrinsics.fx, 525);
  EXPECT_DOUBLE_EQ(c.colourCentreInDepth.x(), 0.025);

  mrpt::config::CConfigFileMemory registered("[CAMERA]\nfx = 525\nfy = 525\n");
  EXPECT_FALSE(RgbdCameraCalibration::loadFromConfig(registered).depthCamera);

  mrpt::config::CConfigFileMemory typo(
      "[CAMERA]\nfx = 525\nfy = 525\n[CAMERA_DEPTH]\nfx = 585\nfy = 585\ncolour_center = [0 0 "
      "0]\n");
  try {
    RgbdCameraCalibration::loadFromConfig(typo);
    FAIL() << "unknown key accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("colour_center"), std::string::npos) << e.what();
  }
  // The colour axes turned and offset: p_colour = R (p_depth - centre).
  mrpt::config::CConfigFileMemory turned(
      "[CAMERA]\nfx = 525\nfy = 525\n[CAMERA_DEPTH]\nfx = 585\nfy = 585\n"
      "colour_centre = [0.025 0 0]\ncolour_rotation = [0 -1 0  1 0 0  0 0 1]\n");
  const Eigen::Vector3d inColour =
      RgbdCameraCalibration::loadFromConfig(turned).depthToColour() * Eigen::Vector3d(1, 2, 3);
  EXPECT_NEAR((inColour - Eigen::Vector3d(-2, 0.975, 3)).norm(), 0, 1e-12) << inColour;
  // A matrix that is no rotation: a reflection, a scale, the rows of another matrix.
  for (const char* wrong :
       {"[1 0 0  0 1 0  0 0 -1]", "[1.01 0 0  0 1 0  0 0 1]", "[1 0 0 0 1 0 0 0]"}) {
    mrpt::config::CConfigFileMemory bad(
        std::string("[CAMERA]\nfx = 525\nfy = 525\n[CAMERA_DEPTH]\nfx = 585\nfy = 585\n"
                    "colour_rotation = ") +
        wrong + "\n");
    try {
      RgbdCameraCalibration::loadFromConfig(bad);
      ADD_FAILURE() << wrong << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("colour_rotation"), std::string::npos) << e.what();
    }
  }
  mrpt::config::CConfigFileMemory zeroFocal(
      "[CAMERA]\nfx = 525\nfy = 525\n[CAMERA_DEPTH]\nfx = 0\n");
  EXPECT_THROW(RgbdCameraCalibration::loadFromConfig(zeroFocal), std::invalid_argument);
}
