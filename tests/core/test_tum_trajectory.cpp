#include <slamdunk/core/TumTrajectory.h>

#include "TestData.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace slamdunk;

namespace {
std::string writeText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}
std::string readText(const std::string& path) {
  std::ifstream f(path);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
}  // namespace

TEST(TumTrajectory, WriteReadRoundTrip) {
  const std::string dir = test::scratchDir("TumTrajectory_RoundTrip");
  Trajectory t;
  for (int i = 0; i < 5; ++i)
    t.push_back({1305031453.359684 + i * 0.033,
                 poseFromTranslationQuaternion(0.1 * i, -0.2, 1.5, 0.1 * i, 0.2, -0.3, 0.9)});
  writeTumTrajectory(dir + "/t.txt", t, "unit test");
  const Trajectory back = readTumTrajectory(dir + "/t.txt");
  ASSERT_EQ(back.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(back[i].timestamp, t[i].timestamp, 1e-6);
    EXPECT_LT((back[i].pose.matrix() - t[i].pose.matrix()).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST(TumTrajectory, ReadsRealGroundTruth) {
  SLAMDUNK_REQUIRE_DATA(gt, "tum/fr1_desk_9f/groundtruth.txt");
  const Trajectory t = readTumTrajectory(gt);
  EXPECT_EQ(t.size(), 2335u);
  EXPECT_NEAR(t.front().timestamp, 1305031449.7996, 1e-6);
  EXPECT_NEAR(t.front().pose.translation().z(), 1.6941, 1e-9);
}

TEST(TumTrajectory, MalformedLinesNameFileAndLine) {
  const std::string dir = test::scratchDir("TumTrajectory_Malformed");
  const std::string good = "# c\n1.0 0 0 0 0 0 0 1\n";
  struct Case {
    std::string text, expect;
  } cases[] = {{good + "2.0 0 0 0 0 0 1\n", ":3: expected 8 fields"},
               {good + "2.0 0 0 x 0 0 0 1\n", ":3: 'x' is not a number"},
               {good + "2.0 0 0 nan 0 0 0 1\n", ":3: non-finite"},
               {good + "2.0 0 0 0 0 0 0 0\n", ":3: pose has a zero-length quaternion"}};
  for (const auto& c : cases) {
    const std::string p = writeText(dir + "/bad.txt", c.text);
    try {
      readTumTrajectory(p);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(p + c.expect), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readTumTrajectory(dir + "/does-not-exist.txt"), std::runtime_error);
}

TEST(TumTrajectory, FailedWriteKeepsExistingFile) {
  const std::string dir = test::scratchDir("TumTrajectory_Atomic");
  const std::string path = writeText(dir + "/keep.txt", "precious\n");
  Trajectory t(1);
  t[0].pose.translation().x() = std::nan("");
  EXPECT_THROW(writeTumTrajectory(path, t), std::runtime_error);
  EXPECT_EQ(readText(path), "precious\n");
  // No temporary file is left behind.
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);
}
