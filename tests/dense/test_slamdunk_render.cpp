// The slamdunk-render tool on a small saved map built here (no dataset needed): a picture on
// success, a clear error and a non-zero exit code on a missing or corrupt map or a bad size.

#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>

#include "TestData.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return "'" + s + "'"; }
using test::readFile;

/// Three keyframes 20 cm apart looking at a tilted, colour-striped wall about 2 m away.
std::string saveSmallMap(const std::string& dir) {
  auto graph = std::make_shared<KeyframeGraph>();
  for (KeyframeId id = 0; id < 3; ++id) {
    auto kf = std::make_shared<Keyframe>();
    kf->id = id;
    kf->timestamp = id;
    kf->depth = cv::Mat(480, 640, CV_32F);
    kf->colour = cv::Mat(480, 640, CV_8UC3);
    for (int v = 0; v < 480; ++v)
      for (int u = 0; u < 640; ++u) {
        kf->depth.at<float>(v, u) = 2.0f + 0.001f * float(u);
        kf->colour.at<cv::Vec3b>(v, u) =
            (u / 80) % 2 ? cv::Vec3b(30, 30, 220) : cv::Vec3b(40, 200, 60);
      }
    Pose T = Pose::Identity();
    T.translation() = Eigen::Vector3d(0.2 * id, 0, 0);
    graph->addKeyframe(kf, T);
  }
  PointMatch m;
  m.pointI = m.pointJ = Eigen::Vector3d(0, 0, 2);
  graph->addMatches(0, 1, {m});
  graph->addMatches(1, 2, {m});
  const std::string path = dir + "/small.map";
  CKeyframeGraphMap(graph).saveToFile(path);
  return path;
}

}  // namespace

TEST(SlamdunkRender, RendersASavedMap) {
  const std::string dir = test::scratchDir("Render_Map");
  const std::string map = saveSmallMap(dir);
  const std::string png = dir + "/map.png", scene = dir + "/map.3Dscene";
  const auto r = test::runCommand(test::toolPath("slamdunk-render") + " " + q(map) + " " + q(png) +
                                  " --width 320 --height 240 --scene " + q(scene));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::cout << r.output;
  EXPECT_NE(r.output.find("dense"), std::string::npos) << r.output;
  const cv::Mat img = cv::imread(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty()) << r.output;
  EXPECT_EQ(img.cols, 320);
  EXPECT_EQ(img.rows, 240);
  // The wall's red and green stripes are in the picture.
  int red = 0, green = 0;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
      red += p[2] > 150 && p[1] < 100;
      green += p[1] > 150 && p[2] < 100;
    }
  EXPECT_GT(red, 500);
  EXPECT_GT(green, 500);
  EXPECT_NO_THROW(MapRenderer::loadScene(scene));
}

TEST(SlamdunkRender, MissingOrCorruptMapIsAClearError) {
  const std::string dir = test::scratchDir("Render_Bad");
  const std::string tool = test::toolPath("slamdunk-render");
  const std::string png = dir + "/out.png";

  auto r = test::runCommand(tool + " " + q(dir + "/nothing.map") + " " + q(png));
  EXPECT_TRUE(test::failedNaming(r, "nothing.map"));

  std::ofstream(dir + "/garbage.map") << "this is not a map";
  r = test::runCommand(tool + " " + q(dir + "/garbage.map") + " " + q(png));
  EXPECT_TRUE(test::failedNaming(r, "garbage.map"));

  // A real map cut in half.
  const std::string map = saveSmallMap(dir);
  fs::resize_file(map, fs::file_size(map) / 2);
  r = test::runCommand(tool + " " + q(map) + " " + q(png));
  EXPECT_TRUE(test::failedNaming(r, "error"));
  EXPECT_FALSE(fs::exists(png)) << "no picture may be written on failure";
}

TEST(SlamdunkRender, BadArgumentsAndHelp) {
  const std::string dir = test::scratchDir("Render_Args");
  const std::string tool = test::toolPath("slamdunk-render");
  const std::string map = saveSmallMap(dir);
  auto r = test::runCommand(tool + " " + q(map) + " " + q(dir + "/x.png") + " --width 0");
  EXPECT_TRUE(test::failedNaming(r, "image size"));
  r = test::runCommand(tool + " " + q(map) + " " + q(dir + "/x.png") + " --elevation 100");
  EXPECT_EQ(r.exitCode, 1) << r.output;
  // The picture written over the map it renders would lose the map.
  const std::string mapBefore = readFile(map);
  r = test::runCommand(tool + " " + q(map) + " " + q(map));
  EXPECT_TRUE(test::failedNaming(r, "is the input MAP"));
  EXPECT_EQ(readFile(map), mapBefore);
  r = test::runCommand(tool + " " + q(map));  // OUT missing
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/x.png"));
  r = test::runCommand(tool + " --help");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("--trajectory"), std::string::npos) << r.output;
}
