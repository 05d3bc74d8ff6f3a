// tum2rawlog on every real sequence in the shared data folder, read back and compared with the
// source PNGs; and its behaviour on bad input.

#include <slamdunk/core/DepthRegistration.h>
#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/core/TumSequence.h>
#include <slamdunk/core/TumTrajectory.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/system/datetime.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

struct Listed {
  double stamp;
  std::string file;
};

// An independent reading of a TUM list (not the project's parser).
std::vector<Listed> readList(const std::string& path) {
  std::vector<Listed> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Listed e;
    s >> e.stamp >> e.file;
    out.push_back(e);
  }
  return out;
}

std::string cameraFor(const std::string& seq) {
  const std::string dir = test::sourceDir() + "/config-ini/cameras/";
  if (seq.rfind("tum/fr1", 0) == 0) return dir + "tum-fr1.ini";
  if (seq.rfind("tum/fr2", 0) == 0) return dir + "tum-fr2.ini";
  if (seq.rfind("tum/fr3", 0) == 0) return dir + "tum-fr3.ini";
  return dir + "7scenes.ini";
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

class Tum2RawlogOnRealData : public ::testing::TestWithParam<std::string> {};

}  // namespace

TEST_P(Tum2RawlogOnRealData, ReadBackMatchesSource) {
  const std::string name = GetParam();
  SLAMDUNK_REQUIRE_DATA(seq, name);
  const bool external = name.rfind("7scenes", 0) == 0;  // also exercises external storage
  // 7-Scenes' first 100 frames: the read-back registers every depth image again. The SLAM
  // tests run on the whole conversion (prepare-test-data.sh).
  const size_t maxFrames = external ? 100 : 0;
  const double factor = external ? 1000.0 : 5000.0;
  std::string safe = name;
  for (char& c : safe)
    if (c == '/') c = '_';
  const std::string dir = test::scratchDir("Tum2Rawlog_" + safe);
  const std::string rawlog = dir + "/seq.rawlog";
  const auto r = test::runCommand(
      test::toolPath("tum2rawlog") + " " + quote(seq) + " " + quote(rawlog) + " --camera " +
      quote(cameraFor(name)) + (external ? " --external-images" : "") +
      (maxFrames ? " --max-frames " + std::to_string(maxFrames) : "") + " -q");
  ASSERT_EQ(r.exitCode, 0) << r.output;

  // Expected pairs: nearest depth stamp for each colour stamp (these sets have no ties).
  const auto rgb = readList(seq + "/rgb.txt");
  const auto depth = readList(seq + "/depth.txt");
  std::vector<std::pair<Listed, Listed>> expected;
  for (const auto& c : rgb) {
    const Listed* best = nullptr;
    for (const auto& d : depth)
      if (std::abs(d.stamp - c.stamp) < 0.02 &&
          (!best || std::abs(d.stamp - c.stamp) < std::abs(best->stamp - c.stamp)))
        best = &d;
    if (best) expected.emplace_back(c, *best);
  }
  if (maxFrames && expected.size() > maxFrames) expected.resize(maxFrames);
  EXPECT_NE(r.output.find("frames:           " + std::to_string(expected.size())),
            std::string::npos)
      << r.output;

  const auto calib = RgbdCameraCalibration::loadFromIni(cameraFor(name));
  EXPECT_EQ(calib.depthCamera.has_value(), external);  // only 7-Scenes is not registered
  RawlogReader reader(rawlog);
  size_t i = 0;
  while (auto obs = reader.next()) {
    ASSERT_LT(i, expected.size());
    // Stamped at the exposure's middle: the camera file's latency before the listed stamp.
    EXPECT_NEAR(mrpt::Clock::toDouble(obs->timestamp),
                expected[i].first.stamp - calib.stampLatencyMs / 1000.0, 1e-6);
    cv::Mat png = cv::imread(seq + "/" + expected[i].second.file, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_16UC1);
    if (calib.depthCamera)  // 7-Scenes: depth registered to colour by the camera file
      png = registerDepthToColour(png, *calib.depthCamera, calib.intrinsics, calib.depthToColour(),
                                  1.0 / calib.depthFactor);
    obs->load();
    ASSERT_EQ(obs->rangeImage.rows(), png.rows);
    const RgbdFrame frame = RgbdFrame::fromObservation(*obs);
    size_t checked = 0;
    for (int y = 3; y < png.rows; y += 37)
      for (int x = 5; x < png.cols; x += 41) {
        const uint16_t raw = png.at<uint16_t>(y, x);
        ASSERT_EQ(obs->rangeImage(y, x), raw) << "frame " << i << " pixel " << x << "," << y;
        EXPECT_NEAR(frame.depth().at<float>(y, x), raw / factor, 1e-6 * (1 + raw / factor));
        ++checked;
      }
    EXPECT_GT(checked, 100u);
    // Colour equals the source image (JPEG decoded by the same OpenCV, PNG exactly).
    const cv::Mat colour = cv::imread(seq + "/" + expected[i].first.file, cv::IMREAD_COLOR);
    EXPECT_EQ(cv::norm(colour, obs->intensityImage.asCvMatRef(), cv::NORM_INF), 0.0);
    obs->unload();
    ++i;
  }
  EXPECT_EQ(i, expected.size());

  const std::string gt = dir + "/seq_groundtruth.txt";
  if (fs::exists(seq + "/groundtruth.txt")) {
    const auto a = readTumTrajectory(seq + "/groundtruth.txt");
    const auto b = readTumTrajectory(gt);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_NEAR(a.back().timestamp, b.back().timestamp, 1e-6);
    EXPECT_LT((a.back().pose.matrix() - b.back().pose.matrix()).cwiseAbs().maxCoeff(), 1e-8);
  } else {
    EXPECT_FALSE(fs::exists(gt));
  }
}

INSTANTIATE_TEST_SUITE_P(AllSequences, Tum2RawlogOnRealData,
                         ::testing::Values("tum/fr1_desk_9f", "tum/fr1_xyz_2f", "tum/fr2_desk_3f",
                                           "tum/fr3_office_2f", "tum/fr3_cabinet_58kf",
                                           "tum/fr1_360_5f_nogt", "7scenes/seq-1000f"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

TEST(Tum2Rawlog, SevenScenesOpensInRawlogEdit) {
  // The suite's own conversion (prepare-test-data.sh: tum2rawlog --external-images), not one
  // more of the 1000 frames.
  REQUIRE_RAWLOG(rawlog, "7scenes");
  if (test::runCommand("command -v rawlog-edit").exitCode != 0)
    SLAMDUNK_SKIP("rawlog-edit (package mrpt-apps) not installed");
  // rawlog-edit finds external images only from the rawlog's folder with a bare name.
  const fs::path path(rawlog);
  const auto r =
      test::runCommand("cd " + quote(path.parent_path().string()) + " && rawlog-edit -i " +
                       quote(path.filename().string()) + " --info");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("Overall number of objects         : 1000"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("RGBD /   1000"), std::string::npos) << r.output;
}

// --stride N keeps every N-th associated pair (the same motion at 1/N the frame rate), counted
// before --max-frames.
TEST(Tum2Rawlog, StrideKeepsEveryNthFrame) {
  SLAMDUNK_REQUIRE_DATA(seq, "tum/fr1_desk_9f");
  const std::string dir = test::scratchDir("Tum2Rawlog_Stride");
  const auto calib = RgbdCameraCalibration::loadFromIni(cameraFor("tum/fr1_desk_9f"));
  const auto rgb = readList(seq + "/rgb.txt");  // every colour image of this set has its depth
  ASSERT_EQ(rgb.size(), 9u);
  auto stampsOf = [&](const std::string& extra) {
    const std::string rawlog = dir + "/seq.rawlog";
    const auto r =
        test::runCommand(test::toolPath("tum2rawlog") + " " + quote(seq) + " " + quote(rawlog) +
                         " --camera " + quote(cameraFor("tum/fr1_desk_9f")) + " -q " + extra);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    std::vector<double> stamps;
    RawlogReader reader(rawlog);
    while (auto obs = reader.next())
      stamps.push_back(mrpt::Clock::toDouble(obs->timestamp) + calib.stampLatencyMs / 1000.0);
    return stamps;
  };
  const auto third = stampsOf("--stride 3");
  ASSERT_EQ(third.size(), 3u);
  for (size_t k = 0; k < third.size(); ++k) EXPECT_NEAR(third[k], rgb[3 * k].stamp, 1e-6) << k;
  const auto limited = stampsOf("--stride 4 --max-frames 2");
  ASSERT_EQ(limited.size(), 2u);
  EXPECT_NEAR(limited[1], rgb[4].stamp, 1e-6);
}

// ---------------------------------------------------------------- bad input

namespace {

/// A copy of fr1_xyz_2f that a test may damage.
std::string damagedCopy(const std::string& testName) {
  const std::string src = test::dataPath("tum/fr1_xyz_2f");
  const std::string dir = test::scratchDir(testName) + "/seq";
  fs::copy(src, dir, fs::copy_options::recursive);
  for (auto& p : fs::recursive_directory_iterator(dir))
    fs::permissions(p.path(), fs::perms::owner_write, fs::perm_options::add);
  fs::permissions(dir, fs::perms::owner_write, fs::perm_options::add);
  return dir;
}

std::string firstListed(const std::string& dir, const std::string& list) {
  return readList(dir + "/" + list).front().file;
}

test::CommandResult convert(const std::string& seq, const std::string& out,
                            const std::string& extra = "") {
  return test::runCommand(test::toolPath("tum2rawlog") + " " + quote(seq) + " " + quote(out) +
                          " -q " + extra);
}

}  // namespace

class Tum2RawlogBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    if (test::dataPath("tum/fr1_xyz_2f").empty())
      SLAMDUNK_SKIP("test data 'tum/fr1_xyz_2f' not found under " << test::dataDir());
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    seq = damagedCopy("Tum2RawlogBad_" + name);
    out = fs::path(seq).parent_path().string() + "/out.rawlog";
    std::ofstream(out) << "precious";  // an earlier result the user must not lose
  }
  void expectFailure(const test::CommandResult& r, const std::string& mustMention) {
    EXPECT_NE(r.exitCode, 0) << r.output;
    EXPECT_LT(r.exitCode, 128) << "crashed: " << r.output;
    EXPECT_NE(r.output.find(mustMention), std::string::npos) << r.output;
    std::ifstream f(out);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), "precious");
  }
  std::string seq, out;
};

TEST_F(Tum2RawlogBadInput, MissingRgbList) {
  fs::remove(seq + "/rgb.txt");
  expectFailure(convert(seq, out), "rgb.txt");
}

TEST_F(Tum2RawlogBadInput, ListedImageMissing) {
  const std::string depth = firstListed(seq, "depth.txt");
  fs::remove(seq + "/" + depth);
  expectFailure(convert(seq, out), depth);
}

TEST_F(Tum2RawlogBadInput, DepthOfWrongSize) {
  const std::string depth = firstListed(seq, "depth.txt");
  cv::imwrite(seq + "/" + depth, cv::Mat(240, 320, CV_16UC1, cv::Scalar(1000)));
  expectFailure(convert(seq, out), "320x240");
}

TEST_F(Tum2RawlogBadInput, EightBitDepth) {
  const std::string depth = firstListed(seq, "depth.txt");
  cv::imwrite(seq + "/" + depth, cv::Mat(480, 640, CV_8UC1, cv::Scalar(10)));
  expectFailure(convert(seq, out), "not a 16-bit");
}

TEST_F(Tum2RawlogBadInput, MalformedListLine) {
  std::ofstream(seq + "/rgb.txt", std::ios::app) << "1305031102.xyz rgb/nothing.png\n";
  expectFailure(convert(seq, out), "rgb.txt:");
}

TEST_F(Tum2RawlogBadInput, UnknownCameraKey) {
  const std::string ini = fs::path(seq).parent_path().string() + "/cam.ini";
  std::ofstream(ini) << "[CAMERA]\nfx = 500\nfy = 500\ncx = 320\ncy = 240\nfocal = 3\n";
  expectFailure(convert(seq, out, "--camera " + quote(ini)), "focal");
}

TEST_F(Tum2RawlogBadInput, ZeroStride) {
  expectFailure(convert(seq, out, "--stride 0"), "--stride");
}

TEST_F(Tum2RawlogBadInput, MissingSequenceFolder) {
  expectFailure(convert(seq + "/nope", out), "nope");
}

TEST_F(Tum2RawlogBadInput, MalformedGroundTruth) {
  std::ofstream(seq + "/groundtruth.txt", std::ios::app) << "1305031102.2 1 2 3\n";
  expectFailure(convert(seq, out), "groundtruth.txt:");
}

// The source's ground truth is read as input: writing the converted copy over it would replace
// the user's file with this tool's (its header and number format), so it is refused.
TEST_F(Tum2RawlogBadInput, GroundTruthOutputOverTheSourcesOwn) {
  const std::string source = seq + "/groundtruth.txt";
  std::ifstream in(source);
  const std::string before((std::istreambuf_iterator<char>(in)), {});
  expectFailure(convert(seq, out, "--gt " + quote(source)), "groundtruth.txt");
  std::ifstream after(source);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(after), {}), before);
}

TEST_F(Tum2RawlogBadInput, RawlogOverAnImageList) {
  const std::string list = seq + "/rgb.txt";
  std::ifstream in(list);
  const std::string before((std::istreambuf_iterator<char>(in)), {});
  const auto r = convert(seq, list);
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("rgb.txt"), std::string::npos) << r.output;
  std::ifstream after(list);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(after), {}), before);
}
