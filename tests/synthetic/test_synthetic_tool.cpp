// The synthetic-rgbd command-line tool end to end.

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumTrajectory.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <TestData.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

using test::readFile;

/// synthetic-rgbd run with `args`.
test::CommandResult syntheticRgbd(const std::string& args) {
  return test::runCommand(test::toolPath("synthetic-rgbd") + " " + args);
}

/// The options of a short hand-held sequence, rendered fast, its images beside the rawlog: the
/// shake's first frames (the whole shake squeezed into a few frames moves so fast between them
/// that each frame took the most renders its motion blur allows, 48).
std::string shortShake(int frames) {
  return " --trajectory shake --first-frames " + std::to_string(frames) +
         " --hand-held --supersampling 1 --external-images -q";
}

}  // namespace

TEST(SyntheticRgbdTool, WritesRawlogAndGroundTruth) {
  const std::string dir = test::scratchDir("synthetic_tool_ok");
  const std::string out = dir + "/sweep10.rawlog";
  const auto r = syntheticRgbd(out + " --trajectory sweep --frames 10");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("frames:"), std::string::npos) << r.output;

  const Trajectory gt = readTumTrajectory(dir + "/sweep10_groundtruth.txt");
  ASSERT_EQ(gt.size(), 10u);
  RawlogReader reader(out);
  size_t n = 0;
  while (auto obs = reader.next()) {
    ASSERT_LT(n, gt.size());
    EXPECT_NEAR(mrpt::Clock::toDouble(obs->timestamp), gt[n].timestamp, 2e-6) << "frame " << n;
    EXPECT_EQ(obs->sensorLabel, "SYNTH_RGBD");
    ++n;
  }
  EXPECT_EQ(n, 10u);
}

TEST(SyntheticRgbdTool, ExternalImagesAndCustomGroundTruthPath) {
  const std::string dir = test::scratchDir("synthetic_tool_external");
  const std::string out = dir + "/loop3.rawlog", gtPath = dir + "/gt.txt";
  const auto r = syntheticRgbd(out +
                               " --trajectory loop --frames 3 --seed 5 --external-images "
                               "--depth-noise 0.001 --gt " +
                               gtPath + " -q");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(readTumTrajectory(gtPath).size(), 3u);
  EXPECT_TRUE(fs::is_directory(dir + "/loop3_Images"));
  RawlogReader reader(out);
  size_t n = 0;
  while (auto obs = reader.next()) {
    const RgbdFrame frame = RgbdFrame::fromObservation(*obs);  // loads the external files
    EXPECT_EQ(frame.grey().cols, 640);
    EXPECT_GT(frame.validDepthFraction(), 0.99);
    ++n;
  }
  EXPECT_EQ(n, 3u);
}

// The twin is what --kinect-depth renders, byte for byte (rawlog, images, ground truth), and the
// exact-depth sequence beside it is what a run without the twin renders.
TEST(SyntheticRgbdTool, KinectTwinIsTheKinectDepthSequence) {
  const std::string dir = test::scratchDir("synthetic_tool_twin");
  const std::string common = shortShake(6);
  auto r = syntheticRgbd(dir + "/exact.rawlog --kinect-twin " + dir + "/twin.rawlog" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = syntheticRgbd(dir + "/alone.rawlog" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = syntheticRgbd(dir + "/kinect.rawlog --kinect-depth" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;

  auto expectSameSequence = [&](const std::string& a, const std::string& b) {
    SCOPED_TRACE(a + " vs " + b);
    EXPECT_EQ(readFile(dir + "/" + a + ".rawlog"), readFile(dir + "/" + b + ".rawlog"));
    EXPECT_EQ(readFile(dir + "/" + a + "_groundtruth.txt"),
              readFile(dir + "/" + b + "_groundtruth.txt"));
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir + "/" + a + "_Images")) {
      const std::string other = dir + "/" + b + "_Images/" + e.path().filename().string();
      ASSERT_TRUE(fs::exists(other)) << other;
      EXPECT_EQ(readFile(e.path().string()), readFile(other)) << e.path();
      ++files;
    }
    EXPECT_EQ(files, 12u);  // 6 colour PNGs, 6 depth matrices
  };
  expectSameSequence("twin", "kinect");
  expectSameSequence("exact", "alone");
  // And the twin's depth really is the Kinect's, not the exact one.
  EXPECT_NE(readFile(dir + "/twin_Images/000003_depth.bin"),
            readFile(dir + "/exact_Images/000003_depth.bin"));

  r = syntheticRgbd(dir + "/k2.rawlog --kinect-depth --kinect-twin " + dir +
                    "/t2.rawlog --frames 3 -q");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("--kinect-twin and --kinect-depth"), std::string::npos) << r.output;
  r = syntheticRgbd(dir + "/k3.rawlog --kinect-twin " + dir + "/./k3.rawlog --frames 3 -q");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("name the same file"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/k2.rawlog"));
  EXPECT_FALSE(fs::exists(dir + "/k3.rawlog"));
}

// --jpeg-quality: colour as JPEG beside the rawlog (the twin hard-links the same files), close
// to the lossless render; the depth is the exact depth PNG output's, byte for byte.
TEST(SyntheticRgbdTool, JpegColourStaysCloseToTheLosslessRender) {
  const std::string dir = test::scratchDir("synthetic_tool_jpeg");
  const std::string common = shortShake(4);
  auto r = syntheticRgbd(dir + "/png.rawlog" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = syntheticRgbd(dir + "/jpg.rawlog --kinect-twin " + dir + "/twin.rawlog" + common +
                    " --jpeg-quality 95");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  // One reader after the other: MRPT resolves external image names against one folder per
  // process, the last reader's.
  auto framesOf = [](const std::string& rawlog) {
    RawlogReader reader(rawlog);
    std::vector<RgbdFrame> frames;
    while (auto obs = reader.next()) frames.push_back(RgbdFrame::fromObservation(*obs));
    return frames;
  };
  const auto lossless = framesOf(dir + "/png.rawlog"), lossy = framesOf(dir + "/jpg.rawlog");
  ASSERT_EQ(lossless.size(), 4u);
  ASSERT_EQ(lossy.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_EQ(cv::norm(lossless[i].depth(), lossy[i].depth(), cv::NORM_INF), 0.0);
    const double meanError = cv::norm(lossless[i].grey(), lossy[i].grey(), cv::NORM_L1) /
                             static_cast<double>(lossless[i].grey().total());
    EXPECT_GT(meanError, 0.0);  // lossy indeed
    EXPECT_LT(meanError, 1.8);  // grey levels; quality 95 measured 0.58-0.93
    char name[32];
    std::snprintf(name, sizeof(name), "/%06zu_rgb.jpg", i);
    EXPECT_TRUE(fs::exists(dir + "/jpg_Images" + name));
    EXPECT_EQ(fs::hard_link_count(dir + "/jpg_Images" + name), 2u);  // the twin's is the same file
    EXPECT_TRUE(fs::exists(dir + "/twin_Images" + name));
  }

  r = syntheticRgbd(dir + "/bad.rawlog" + common + " --jpeg-quality 101");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("JPEG quality must be"), std::string::npos) << r.output;
  r = syntheticRgbd(dir + "/bad.rawlog --frames 3 -q --jpeg-quality 90");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("needs external images"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/bad.rawlog"));
}

TEST(SyntheticRgbdTool, BadOptionFailsClearlyAndKeepsExistingFiles) {
  const std::string dir = test::scratchDir("synthetic_tool_bad");
  const std::string out = dir + "/keep.rawlog", gtPath = dir + "/keep_groundtruth.txt";
  std::ofstream(out) << "precious";
  std::ofstream(gtPath) << "precious too";

  auto r = syntheticRgbd(out + " --trajectory nope");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("unknown trajectory 'nope'"), std::string::npos) << r.output;

  r = syntheticRgbd(out + " --frames 1");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("frames"), std::string::npos) << r.output;

  r = syntheticRgbd(out + " --no-such-option");
  EXPECT_NE(r.exitCode, 0);

  r = syntheticRgbd(out + " --frames many");
  EXPECT_NE(r.exitCode, 0);

  // The ground truth written over the rawlog, under another spelling of its path.
  r = syntheticRgbd(out + " --gt " + dir + "/./keep.rawlog --frames 3");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("name the same file"), std::string::npos) << r.output;

  EXPECT_EQ(readFile(out), "precious");
  EXPECT_EQ(readFile(gtPath), "precious too");
  // No temporary files left behind.
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u);

  r = syntheticRgbd("--help");
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.output.find("--trajectory"), std::string::npos);
}
