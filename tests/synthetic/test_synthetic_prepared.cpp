// The office tours the suite prepares (tests/apps/prepare-test-data.sh) checked as renders: the
// bare corridor against the painted one, and the tool rendering the same frames again byte for
// byte. Reading the prepared frames instead of rendering the office anew saves its textures
// (about 6 s of CPU each).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/TumTrajectory.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <TestData.h>
#include "KeypointSpread.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string colourFile(size_t frame) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu_rgb.jpg", frame);
  return name;
}

}  // namespace

TEST(SyntheticSequence, TheBareCorridorGivesFewKeypoints) {
  // The tour's frame in the middle of the corridor from B to C, with and without its paint (the
  // twin-room tour's colour camera and path are the drifting tour's; its room C, a copy of A, is
  // not in this view): fewer than half the keypoints, most of them on the corridor's cabinets.
  REQUIRE_RAWLOG(textured, "tour_twins");
  REQUIRE_RAWLOG(bare, "tour_drift_bare");
  const Trajectory gt = readTumTrajectory(test::groundTruthOf(bare));
  size_t i = 0;
  while (i < gt.size()) {
    const Eigen::Vector3d p = gt[i].pose.translation();
    if (std::abs(p.x() - 16.0) < 0.5 && p.z() > 6.0) break;
    ++i;
  }
  ASSERT_LT(i, gt.size()) << "the tour no longer walks the corridor from B to C";
  const cv::Mat texturedImage =
      cv::imread(RawlogReader::imagesDirectoryFor(textured) + "/" + colourFile(i));
  const cv::Mat bareImage =
      cv::imread(RawlogReader::imagesDirectoryFor(bare) + "/" + colourFile(i));
  ASSERT_FALSE(texturedImage.empty() || bareImage.empty()) << "frame " << i;
  const size_t before = test::keypointSpread(texturedImage).keypoints;
  const size_t after = test::keypointSpread(bareImage).keypoints;
  std::printf("[ bare corridor ] frame %zu: %zu ORB keypoints, %zu textured\n", i, after, before);
  EXPECT_LT(after, before / 2);
  EXPECT_GT(after, 0u) << "the corridor's cabinets keep their texture";
}

TEST(SyntheticRgbdTool, TourWithKinectDepthAndExternalImagesIsDeterministic) {
  // The first frames of the drifting tour with a bare corridor through the command line again
  // (the options of a benchmark: textures, Kinect noise, a focal length stated wrong, JPEG
  // colour): the files of the prepared tour, byte for byte. (The preparation renders again when
  // the renderer's library changed; a change elsewhere that alters the renders is caught here.)
  REQUIRE_RAWLOG(prepared, "tour_drift_bare");
  const std::string dir = test::scratchDir("synthetic_tool_tour");
  const auto r = test::runCommand(
      test::toolPath("synthetic-rgbd") + " " + dir +
      "/again.rawlog --trajectory tour --frames 1100 --first-frames 2 --kinect-depth "
      "--stated-focal-error 3 --bare-corridor --external-images --jpeg-quality 95 "
      "--supersampling 1 -q");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("scene:            office"), std::string::npos) << r.output;
  size_t compared = 0;
  for (const auto& e : fs::directory_iterator(dir + "/again_Images")) {
    const fs::path original =
        fs::path(RawlogReader::imagesDirectoryFor(prepared)) / e.path().filename();
    EXPECT_EQ(test::readFile(e.path().string()), test::readFile(original.string()))
        << e.path().filename() << " differs from the prepared " << original;
    ++compared;
  }
  EXPECT_EQ(compared, 4u);  // colour and depth of 2 frames
  const auto again = test::tumPoseLines(dir + "/again_groundtruth.txt");
  const auto all = test::tumPoseLines(test::groundTruthOf(prepared));
  ASSERT_EQ(again.size(), 2u);
  ASSERT_GE(all.size(), 2u);
  EXPECT_EQ(again[0], all[0]);
  EXPECT_EQ(again[1], all[1]);
}
