// Dense outputs of a real SLAM run (7-Scenes, 1000 frames): the cloud from the optimised
// keyframe poses against the same keyframes posed by ground truth, PLY/PCD and OctoMap files
// written and read back, and a rendered picture. The run is the suite's shared one
// (shared_run_7scenes: slamdunk-rawlog with the shipped INI, keyframe images in its map).

#include <slamdunk/core/TimestampAssociation.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/dense/DenseOutputs.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/eval/RigidAlignment.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <nanoflann.hpp>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <set>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// nanoflann adaptor straight over the cloud's points (no copy).
struct CloudAdaptor {
  const std::vector<Eigen::Vector3f>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(size_t i, size_t d) const { return pts[i][int(d)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>,
                                        CloudAdaptor, 3, size_t>;

/// Distance from each point of `from` to its nearest neighbour in `to`, sorted.
std::vector<double> nearestDistances(const DenseCloud& from, const DenseCloud& to) {
  CloudAdaptor adaptor{to.points};
  KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  std::vector<double> d(from.size());
  for (size_t i = 0; i < from.size(); ++i) {
    size_t index = 0;
    float sq = 0;
    tree.knnSearch(from.points[i].data(), 1, &index, &sq);
    d[i] = std::sqrt(double(sq));
  }
  std::sort(d.begin(), d.end());
  return d;
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[size_t(q * double(sorted.size() - 1))];
}

}  // namespace

class SevenScenesDense : public ::testing::Test {
 protected:
  /// The occupancy grid at 4 cm, twice the default's voxel, from every 16th depth pixel: the
  /// default (2 cm, every 8th) took 15 s of this test's 55. slamdunk-rawlog --dense writes the
  /// default's (SlamdunkRawlogMaps.WritesMapDenseOutputsPictureAndSimpleMap).
  static DenseOutputOptions outputOptions() {
    DenseOutputOptions o;
    o.occupancy.resolution = 0.04;
    o.occupancy.pixelStride = 16;
    return o;
  }

  static void SetUpTestSuite() {
    rawlog_ = test::preparedRawlog("7scenes");
    const std::string run = test::sharedRunDir("7scenes");
    if (rawlog_.empty() || run.empty()) return;
    graph_ = CKeyframeGraphMap::loadFromFile(run + "/run.map")->graph();
    trajectory_ = readTumTrajectory(run + "/trajectory.txt");
    std::cout << "[ 7scenes ] SLAM: " << graph_->keyframeCount() << " keyframes\n";
    dir_ = test::scratchDir("Dense_7Scenes");
    const auto t1 = std::chrono::steady_clock::now();
    summary_ = writeDenseOutputs(*graph_, dir_ + "/map", outputOptions());
    std::cout << "[ 7scenes ] dense outputs in " << secondsSince(t1)
              << " s: " << summary_.keyframesWithImages << " keyframes, " << summary_.cloudPoints
              << " cloud points (" << summary_.cloudSeconds << " s), "
              << summary_.occupancy.occupiedLeaves << " occupied + "
              << summary_.occupancy.freeLeaves << " free leaves at "
              << summary_.occupancy.resolution << " m (" << summary_.occupancySeconds << " s, "
              << summary_.occupancy.memoryBytes / 1024 << " KiB)\n";
  }
  static void TearDownTestSuite() { graph_.reset(); }

  void SetUp() override {
    if (!graph_)
      SLAMDUNK_SKIP("the shared run '7scenes' was not made (its source data is not under "
                    << test::dataDir() << ", or the test shared_run_7scenes did not run)");
  }

  static inline std::string rawlog_, dir_;
  static inline std::shared_ptr<KeyframeGraph> graph_;
  static inline Trajectory trajectory_;
  static inline DenseOutputSummary summary_;
};

TEST_F(SevenScenesDense, CloudMatchesTheGroundTruthPosedCloud) {
  const auto keyframes = keyframesWithImages(*graph_);
  ASSERT_GE(keyframes.size(), 5u);

  // Ground-truth pose of each keyframe (by timestamp).
  const Trajectory gt =
      readTumTrajectory((fs::path(rawlog_).parent_path() / "7scenes_groundtruth.txt").string());
  std::vector<double> kfStamps, gtStamps;
  for (const auto& k : keyframes) kfStamps.push_back(k.keyframe->timestamp);
  for (const auto& s : gt) gtStamps.push_back(s.timestamp);
  const auto pairs = associateTimestamps(kfStamps, gtStamps, 0.005);
  ASSERT_EQ(pairs.size(), keyframes.size()) << "keyframes without a ground-truth pose";

  // Ground truth lives in its own world: align it rigidly onto the estimated keyframe positions.
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [k, g] : pairs) {
    src.push_back(gt[g].pose.translation());
    dst.push_back(keyframes[k].pose.translation());
  }
  const Pose align = eval::RigidAlignment::compute(src, dst).transform();
  std::vector<PosedKeyframe> gtKeyframes;
  double ateSq = 0;
  for (const auto& [k, g] : pairs) {
    gtKeyframes.push_back({keyframes[k].keyframe, align * gt[g].pose});
    ateSq +=
        (gtKeyframes.back().pose.translation() - keyframes[k].pose.translation()).squaredNorm();
  }

  DenseOptions options;  // defaults: stride 2, 1 cm voxels
  const auto t0 = std::chrono::steady_clock::now();
  const DenseCloud estimated = buildDenseCloud(keyframes, options);
  const double buildSeconds = secondsSince(t0);
  const DenseCloud reference = buildDenseCloud(gtKeyframes, options);
  ASSERT_GT(estimated.size(), 10000u);
  ASSERT_GT(reference.size(), 10000u);

  const std::vector<double> d = nearestDistances(estimated, reference);
  const double median = quantile(d, 0.5);
  std::cout << "[ 7scenes ] keyframe ATE rmse " << std::sqrt(ateSq / double(pairs.size()))
            << " m; estimated cloud " << estimated.size() << " points (" << buildSeconds
            << " s), reference " << reference.size()
            << "; NN distance estimated->reference: median " << median * 100 << " cm, p90 "
            << quantile(d, 0.9) * 100 << " cm\n";
  EXPECT_LE(median, 0.03);

  // The bound can fail: the same keyframes with poses 10 cm and 5 degrees off exceed it.
  std::vector<PosedKeyframe> perturbed = keyframes;
  for (size_t i = 0; i < perturbed.size(); ++i) {
    const double s = (i % 2 ? 1.0 : -1.0);
    perturbed[i].pose = perturbed[i].pose * Eigen::Translation3d(0.1 * s, -0.1 * s, 0) *
                        Eigen::AngleAxisd(s * 5 * M_PI / 180, Eigen::Vector3d::UnitY());
  }
  const double perturbedMedian =
      quantile(nearestDistances(buildDenseCloud(perturbed, options), reference), 0.5);
  std::cout << "[ 7scenes ] perturbed poses: median " << perturbedMedian * 100 << " cm\n";
  EXPECT_GT(perturbedMedian, 0.03);
}

TEST_F(SevenScenesDense, PlyAndPcdAreWrittenAndReadable) {
  ASSERT_GT(summary_.cloudPoints, 0u);
  for (const std::string ext : {".ply", ".pcd"}) {
    const std::string path = dir_ + "/map" + ext;
    ASSERT_TRUE(fs::exists(path)) << path;
    const DenseCloud c = readPointCloud(path);  // pcl::io
    EXPECT_EQ(c.size(), summary_.cloudPoints) << path;
    std::set<DenseCloud::Rgb> distinct(c.colours.begin(), c.colours.end());
    EXPECT_GT(distinct.size(), 100u) << path << ": colours missing";
    Eigen::Vector3f lo, hi;
    ASSERT_TRUE(c.boundingBox(lo, hi));
    EXPECT_GT((hi - lo).minCoeff(), 0.5f) << path << ": a room should be more than 50 cm deep";
  }
  // Atomic writes leave no temporary files: exactly the four outputs.
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"map.bt", "map.ot", "map.pcd", "map.ply"}));
}

TEST_F(SevenScenesDense, OctoMapFilesReadBack) {
  const double res = outputOptions().occupancy.resolution;
  const OccupancyStatistics& s = summary_.occupancy;
  // Measured 13,577 occupied and 184,584 free leaves.
  EXPECT_GT(s.occupiedLeaves, 9000u);
  EXPECT_GT(s.freeLeaves, 120000u);

  // Colour tree (.ot).
  std::unique_ptr<octomap::AbstractOcTree> abstractTree(
      octomap::AbstractOcTree::read(dir_ + "/map.ot"));
  auto* colour = dynamic_cast<octomap::ColorOcTree*>(abstractTree.get());
  ASSERT_TRUE(colour) << "map.ot is not a ColorOcTree";
  EXPECT_DOUBLE_EQ(colour->getResolution(), res);
  // Bounding box of occupied voxels: inside the cloud's box (plus one voxel), and the cameras'
  // own cells were only ever crossed by rays: known and free.
  const DenseCloud cloud = readPointCloud(dir_ + "/map.ply");
  Eigen::Vector3f lo, hi;
  ASSERT_TRUE(cloud.boundingBox(lo, hi));
  size_t occupied = 0, free = 0, coloured = 0;
  std::set<std::array<uint8_t, 3>> colours;
  for (auto it = colour->begin_leafs(); it != colour->end_leafs(); ++it) {
    if (colour->isNodeOccupied(*it)) {
      ++occupied;
      const Eigen::Vector3f c(it.getX(), it.getY(), it.getZ());
      ASSERT_TRUE((c.array() >= lo.array() - 2 * float(res)).all() &&
                  (c.array() <= hi.array() + 2 * float(res)).all())
          << "occupied voxel outside the cloud's box: " << c.transpose();
      if (it->isColorSet()) {
        ++coloured;
        const auto col = it->getColor();
        colours.insert({col.r, col.g, col.b});
      }
    } else {
      ++free;
    }
  }
  EXPECT_EQ(occupied, s.occupiedLeaves);
  EXPECT_EQ(free, s.freeLeaves);
  EXPECT_GT(coloured, occupied * 9 / 10) << "colours were not integrated";
  EXPECT_GT(colours.size(), 100u);
  for (const auto& pk : keyframesWithImages(*graph_)) {
    const Eigen::Vector3d c = pk.pose.translation();
    const auto* node = colour->search(c.x(), c.y(), c.z());
    ASSERT_TRUE(node) << "camera centre of keyframe " << pk.keyframe->id << " is unknown";
    EXPECT_FALSE(colour->isNodeOccupied(node)) << "keyframe " << pk.keyframe->id;
  }

  // Binary occupancy (.bt): same resolution and the same occupied volume.
  octomap::OcTree binary(0.1);
  ASSERT_TRUE(binary.readBinary(dir_ + "/map.bt"));
  EXPECT_DOUBLE_EQ(binary.getResolution(), res);
  double occupiedVolume = 0;
  size_t binaryFree = 0;
  for (auto it = binary.begin_leafs(); it != binary.end_leafs(); ++it) {
    if (binary.isNodeOccupied(*it))
      occupiedVolume += std::pow(it.getSize(), 3);
    else
      ++binaryFree;
  }
  EXPECT_NEAR(occupiedVolume, s.occupiedVolume, 1e-3 * s.occupiedVolume);
  EXPECT_GT(binaryFree, 0u);
  std::cout << "[ 7scenes ] octomap: occupied " << s.occupiedLeaves << " leaves ("
            << s.occupiedVolume << " m3), free " << s.freeLeaves << " (" << s.freeVolume
            << " m3), occupied box " << s.occupiedMin.transpose() << " .. "
            << s.occupiedMax.transpose() << "\n";
}

TEST_F(SevenScenesDense, RendersTheMapHeadless) {
  RenderOptions options;
  options.width = 640;
  options.height = 480;
  MapRenderer renderer(options);
  renderer.setCloud(readPointCloud(dir_ + "/map.ply"));
  renderer.setGraph(*graph_);
  renderer.setTrajectory(trajectory_);
  const auto t0 = std::chrono::steady_clock::now();
  const auto scene = renderer.buildScene();
  renderer.renderPng(*scene, dir_ + "/../Dense_7Scenes_render.png");
  const double seconds = secondsSince(t0);
  MapRenderer::saveScene(*scene, dir_ + "/../Dense_7Scenes.3Dscene");
  std::cout << "[ 7scenes ] rendered 640x480 in " << seconds * 1000 << " ms\n";

  const cv::Mat img = cv::imread(dir_ + "/../Dense_7Scenes_render.png", cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 640);
  ASSERT_EQ(img.rows, 480);
  const cv::Vec3b bg = img.at<cv::Vec3b>(0, 0);
  size_t nonBg = 0;
  std::set<int> distinct;
  for (int v = 0; v < img.rows; ++v)
    for (int u = 0; u < img.cols; ++u) {
      const cv::Vec3b p = img.at<cv::Vec3b>(v, u);
      if (p == bg) continue;
      ++nonBg;
      distinct.insert((p[0] >> 3) << 10 | (p[1] >> 3) << 5 | (p[2] >> 3));
    }
  std::cout << "[ 7scenes ] " << 100.0 * nonBg / img.total() << "% of pixels drawn, "
            << distinct.size() << " distinct colours\n";
  EXPECT_GT(nonBg, img.total() / 8);
  EXPECT_GT(distinct.size(), 500u);
  EXPECT_NO_THROW(MapRenderer::loadScene(dir_ + "/../Dense_7Scenes.3Dscene"));
}
