// The synthetic-rgbd command-line tool end to end.

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumTrajectory.h>

#include <gtest/gtest.h>

#include <TestData.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

using test::readFile;

}  // namespace

TEST(SyntheticRgbdTool, WritesRawlogAndGroundTruth) {
  const std::string dir = test::scratchDir("synthetic_tool_ok");
  const std::string out = dir + "/sweep10.rawlog";
  const auto r = test::runCommand(test::toolPath("synthetic-rgbd") + " " + out +
                                  " --trajectory sweep --frames 10");
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
  const auto r = test::runCommand(test::toolPath("synthetic-rgbd") + " " + out +
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
  const std::string tool = test::toolPath("synthetic-rgbd");
  const std::string common =
      " --trajectory shake --frames 6 --hand-held --supersampling 1 "
      "--external-images -q";
  auto r = test::runCommand(tool + " " + dir + "/exact.rawlog --kinect-twin " + dir +
                            "/twin.rawlog" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = test::runCommand(tool + " " + dir + "/alone.rawlog" + common);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  r = test::runCommand(tool + " " + dir + "/kinect.rawlog --kinect-depth" + common);
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

  r = test::runCommand(tool + " " + dir + "/k2.rawlog --kinect-depth --kinect-twin " + dir +
                       "/t2.rawlog --frames 3 -q");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("--kinect-twin and --kinect-depth"), std::string::npos) << r.output;
  r = test::runCommand(tool + " " + dir + "/k3.rawlog --kinect-twin " + dir +
                       "/./k3.rawlog --frames 3 -q");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("name the same file"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/k2.rawlog"));
  EXPECT_FALSE(fs::exists(dir + "/k3.rawlog"));
}

TEST(SyntheticRgbdTool, BadOptionFailsClearlyAndKeepsExistingFiles) {
  const std::string dir = test::scratchDir("synthetic_tool_bad");
  const std::string out = dir + "/keep.rawlog", gtPath = dir + "/keep_groundtruth.txt";
  std::ofstream(out) << "precious";
  std::ofstream(gtPath) << "precious too";
  const std::string tool = test::toolPath("synthetic-rgbd");

  auto r = test::runCommand(tool + " " + out + " --trajectory nope");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("unknown trajectory 'nope'"), std::string::npos) << r.output;

  r = test::runCommand(tool + " " + out + " --frames 1");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("frames"), std::string::npos) << r.output;

  r = test::runCommand(tool + " " + out + " --no-such-option");
  EXPECT_NE(r.exitCode, 0);

  r = test::runCommand(tool + " " + out + " --frames many");
  EXPECT_NE(r.exitCode, 0);

  // The ground truth written over the rawlog, under another spelling of its path.
  r = test::runCommand(tool + " " + out + " --gt " + dir + "/./keep.rawlog --frames 3");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("name the same file"), std::string::npos) << r.output;

  EXPECT_EQ(readFile(out), "precious");
  EXPECT_EQ(readFile(gtPath), "precious too");
  // No temporary files left behind.
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u);

  r = test::runCommand(tool + " --help");
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.output.find("--trajectory"), std::string::npos);
}
