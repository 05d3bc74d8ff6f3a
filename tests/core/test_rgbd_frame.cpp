#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/system/datetime.h>

#include <opencv2/core.hpp>

#include <initializer_list>

using namespace slamdunk;

namespace {
// A small observation with a known depth ramp and a known colour pattern.
mrpt::obs::CObservation3DRangeScan::Ptr makeObservation(int w, int h) {
  auto obs = mrpt::obs::CObservation3DRangeScan::Create();
  obs->timestamp = mrpt::Clock::fromDouble(12.5);
  obs->hasIntensityImage = true;
  obs->intensityImage.resize(w, h, mrpt::img::CH_RGB);
  cv::Mat& bgr = obs->intensityImage.asCvMatRef();
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(c % 256, r % 256, 100);
  obs->hasRangeImage = true;
  obs->range_is_depth = true;
  obs->rangeImage_setSize(h, w);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) obs->rangeImage(r, c) = static_cast<uint16_t>(5000 + 10 * c);
  obs->rangeImage(0, 0) = 0;
  obs->rangeUnits = 1.0f / 5000;
  CameraIntrinsics K;
  K.width = w;
  K.height = h;
  K.fx = K.fy = 20;
  K.cx = w / 2.0;
  K.cy = h / 2.0;
  obs->cameraParamsIntensity = K.toTCamera();
  obs->cameraParams = obs->cameraParamsIntensity;
  return obs;
}

/// RgbdFrame::fromObservation() refuses `obs`, with a message naming every one of `parts`.
::testing::AssertionResult refusedNaming(const mrpt::obs::CObservation3DRangeScan& obs,
                                         std::initializer_list<std::string> parts) {
  try {
    RgbdFrame::fromObservation(obs);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    std::string missing;
    for (const std::string& part : parts)
      if (what.find(part) == std::string::npos) missing += " '" + part + "'";
    if (missing.empty()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "refused, but without" << missing << ": " << what;
  }
  return ::testing::AssertionFailure() << "accepted";
}
}  // namespace

TEST(RgbdFrame, FromObservationConvertsDepthAndGrey) {
  const auto obs = makeObservation(64, 48);
  const RgbdFrame f = RgbdFrame::fromObservation(*obs);
  EXPECT_DOUBLE_EQ(f.timestamp(), 12.5);
  ASSERT_EQ(f.grey().type(), CV_8UC1);
  ASSERT_EQ(f.depth().type(), CV_32FC1);
  EXPECT_EQ(f.grey().cols, 64);
  EXPECT_FLOAT_EQ(f.depth().at<float>(3, 10), (5000 + 100) * (1.0f / 5000));
  EXPECT_EQ(f.depthAt(0, 0), 0.f);   // invalid pixel
  EXPECT_EQ(f.depthAt(-1, 5), 0.f);  // outside
  EXPECT_FALSE(f.backProject(0, 0));
  const auto p = f.backProject(32 + 20, 24);  // one focal length right of the centre
  ASSERT_TRUE(p);
  const double z = (5000 + 10 * 52) / 5000.0;
  EXPECT_NEAR(p->z(), z, 1e-6);
  EXPECT_NEAR(p->x(), z, 1e-6);
  EXPECT_NEAR(p->y(), 0, 1e-9);
  EXPECT_NEAR(f.validDepthFraction(), 1.0 - 1.0 / (64 * 48), 1e-9);
}

TEST(RgbdFrame, RejectsInconsistentObservations) {
  auto noColour = makeObservation(32, 24);
  noColour->hasIntensityImage = false;
  EXPECT_THROW(RgbdFrame::fromObservation(*noColour), std::runtime_error);

  auto noDepth = makeObservation(32, 24);
  noDepth->hasRangeImage = false;
  EXPECT_THROW(RgbdFrame::fromObservation(*noDepth), std::runtime_error);

  auto wrongSize = makeObservation(32, 24);
  wrongSize->rangeImage_setSize(12, 16);
  EXPECT_TRUE(refusedNaming(*wrongSize, {"16x12"})) << "size mismatch";
}

// Intrinsics of another resolution than the image (a 640x480 calibration on a 320x240 stream)
// would put every point in the wrong place: a clear error naming both sizes, never a guess.
TEST(RgbdFrame, RejectsIntrinsicsOfAnotherResolution) {
  auto halfSize = makeObservation(64, 48);
  halfSize->cameraParamsIntensity.ncols = 128;
  halfSize->cameraParamsIntensity.nrows = 96;
  EXPECT_TRUE(refusedNaming(
      *halfSize, {"at t=12.5", "colour image is 64x48", "cameraParamsIntensity) are for 128x96"}))
      << "colour intrinsics of another resolution";

  // Depth registered to colour: the depth camera's intrinsics must fit the depth image too.
  auto depthCamera = makeObservation(64, 48);
  depthCamera->relativePoseIntensityWRTDepth =
      mrpt::poses::CPose3D(0.025, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  depthCamera->cameraParams.ncols = 640;
  depthCamera->cameraParams.nrows = 480;
  EXPECT_TRUE(
      refusedNaming(*depthCamera, {"depth image is 64x48", "cameraParams) are for 640x480"}))
      << "depth intrinsics of another resolution";

  // A resolution left unset by a driver is the image's.
  auto unset = makeObservation(64, 48);
  unset->cameraParamsIntensity.ncols = 0;
  unset->cameraParamsIntensity.nrows = 0;
  const RgbdFrame f = RgbdFrame::fromObservation(*unset);
  EXPECT_EQ(f.intrinsics().width, 64);
  EXPECT_EQ(f.intrinsics().height, 48);
}

TEST(RgbdFrame, ReadsMrptSampleRawlog) {
  SLAMDUNK_REQUIRE_DATA(path, "mrpt/tests_rgbd.rawlog");
  RawlogReader reader(path);
  auto obs = reader.next();
  ASSERT_TRUE(obs);
  const RgbdFrame f = RgbdFrame::fromObservation(*obs);
  EXPECT_EQ(f.grey().size(), f.depth().size());
  EXPECT_GT(f.validDepthFraction(), 0.3);
  double maxDepth;
  cv::minMaxLoc(f.depth(), nullptr, &maxDepth);
  EXPECT_GT(maxDepth, 0.3);
  EXPECT_LT(maxDepth, 15.0);
  EXPECT_FALSE(reader.next());
}
