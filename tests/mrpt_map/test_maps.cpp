// The keyframe map plug-in (CKeyframeGraphMap), the MRPT map builder (CSlamDunkMapBuilder) and
// the .simplemap export: exact round trips, plug-in loading by a program that links only MRPT,
// CMultiMetricMap declaration from an INI, visualization, bad files, and MRPT's own tools.
// Rawlogs come from the prepare_test_data fixture (<build>/test-data).

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/mrpt_slam/CSlamDunkMapBuilder.h>
#include <slamdunk/slam/SimpleMapExport.h>
#include <slamdunk/slam/SlamSystem.h>

#include "TestData.h"

#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/opengl/CFrustum.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/core.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string q(const std::string& s) { return test::shellQuote(s); }

SlamOptions optionsWithImages() {
  SlamOptions o;
  o.tracker.keepKeyframeImages = true;
  return o;
}

/// The synthetic sweep's map (150 frames, keyframe images kept), made once for the suite by
/// the prepare_sweep_map test (slamdunk-rawlog --map-images, the built-in defaults), read once
/// per process.
std::shared_ptr<KeyframeGraph> sweepGraph() {
  static std::shared_ptr<KeyframeGraph> graph;
  if (!graph && fs::exists(SLAMDUNK_SWEEP_MAP))
    graph = CKeyframeGraphMap::loadFromFile(SLAMDUNK_SWEEP_MAP)->graph();
  return graph;
}

#define REQUIRE_SWEEP_GRAPH(var)                                                        \
  const auto var = sweepGraph();                                                        \
  if (!var)                                                                             \
  SLAMDUNK_SKIP("the synthetic sweep's map " << SLAMDUNK_SWEEP_MAP                      \
                                             << " was not made (the prepare_sweep_map " \
                                                "test)")

bool sameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.rows != b.rows || a.cols != b.cols || a.type() != b.type()) return false;
  if (a.empty()) return true;
  const cv::Mat ca = a.isContinuous() ? a : a.clone(), cb = b.isContinuous() ? b : b.clone();
  return std::memcmp(ca.data, cb.data, ca.total() * ca.elemSize()) == 0;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <typename M>
bool sameBits(const M& a, const M& b) {
  for (Eigen::Index k = 0; k < a.size(); ++k)
    if (!sameBits(a.data()[k], b.data()[k])) return false;
  return true;
}

/// Expects loadFromFile(path) to throw std::runtime_error whose message names the file and
/// contains `expected`; returns the message.
std::string expectLoadError(const std::string& path, const std::string& expected) {
  try {
    CKeyframeGraphMap::loadFromFile(path);
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'" + path + "'"), std::string::npos) << msg;
    EXPECT_NE(msg.find(expected), std::string::npos) << msg;
    return msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a std::runtime_error: " << e.what();
    return {};
  }
  ADD_FAILURE() << "loading '" << path << "' did not throw";
  return {};
}

void writeBytes(const std::string& path, const std::vector<char>& bytes, bool gz) {
  if (gz) {
    mrpt::io::CFileGZOutputStream f(path);
    f.Write(bytes.data(), bytes.size());
  } else {
    std::ofstream f(path, std::ios::binary);
    f.write(bytes.data(), std::streamsize(bytes.size()));
  }
}

std::vector<char> readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(f), {});
}

/// Object of the given name (depth-first) inside a CSetOfObjects.
mrpt::opengl::CRenderizable::Ptr findByName(const mrpt::opengl::CSetOfObjects& set,
                                            const std::string& name) {
  for (const auto& o : set) {
    if (!o) continue;
    if (o->getName() == name) return o;
    if (auto sub = std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(o))
      if (auto found = findByName(*sub, name)) return found;
  }
  return nullptr;
}

/// The graph's keyframes and poses without their images (and, when withEdges, its edges).
std::shared_ptr<KeyframeGraph> withoutImages(const KeyframeGraph& graph, bool withEdges) {
  auto stripped = std::make_shared<KeyframeGraph>();
  for (const auto& [id, pose] : graph.poses()) {
    auto kf = std::make_shared<Keyframe>(*graph.keyframe(id));
    kf->colour = cv::Mat();
    kf->depth = cv::Mat();
    stripped->addKeyframe(kf, pose);
  }
  if (withEdges)
    for (const KeyframeEdge& e : graph.allEdges()) stripped->addMatches(e.i, e.j, e.matches);
  return stripped;
}

}  // namespace

// ------------------------------------------------------------------ serialization

TEST(KeyframeGraphMap, RoundTripIsExact) {
  REQUIRE_SWEEP_GRAPH(graph);
  ASSERT_GE(graph->keyframeCount(), 2u) << "the sweep should create several keyframes";
  ASSERT_GE(graph->edgeCount(), 1u);
  const std::string dir = test::scratchDir("Maps_RoundTrip");
  const std::string path = dir + "/map.kfmap";

  const CKeyframeGraphMap map(graph);
  map.saveToFile(path);
  ASSERT_TRUE(fs::exists(path));
  // gz magic bytes: the file is compressed.
  const auto bytes = readBytes(path);
  ASSERT_GE(bytes.size(), 2u);
  EXPECT_EQ(uint8_t(bytes[0]), 0x1f);
  EXPECT_EQ(uint8_t(bytes[1]), 0x8b);

  const auto loaded = CKeyframeGraphMap::loadFromFile(path);
  const KeyframeGraph& g2 = *loaded->graph();
  ASSERT_EQ(g2.ids(), graph->ids());
  size_t withImages = 0;
  for (KeyframeId id : graph->ids()) {
    SCOPED_TRACE("keyframe " + std::to_string(id));
    EXPECT_TRUE(sameBits(graph->pose(id).matrix(), g2.pose(id).matrix()));
    const Keyframe &a = *graph->keyframe(id), &b = *g2.keyframe(id);
    EXPECT_EQ(a.id, b.id);
    EXPECT_TRUE(sameBits(a.timestamp, b.timestamp));
    EXPECT_EQ(a.intrinsics.width, b.intrinsics.width);
    EXPECT_EQ(a.intrinsics.height, b.intrinsics.height);
    EXPECT_TRUE(
        sameBits(a.intrinsics.fx, b.intrinsics.fx) && sameBits(a.intrinsics.fy, b.intrinsics.fy) &&
        sameBits(a.intrinsics.cx, b.intrinsics.cx) && sameBits(a.intrinsics.cy, b.intrinsics.cy));
    EXPECT_EQ(a.intrinsics.dist, b.intrinsics.dist);
    ASSERT_EQ(a.features.size(), b.features.size());
    ASSERT_GT(a.features.size(), 0u);
    for (size_t k = 0; k < a.features.size(); ++k) {
      const cv::KeyPoint &ka = a.features.keypoints[k], &kb = b.features.keypoints[k];
      EXPECT_TRUE(ka.pt == kb.pt && ka.size == kb.size && ka.angle == kb.angle &&
                  ka.response == kb.response && ka.octave == kb.octave &&
                  ka.class_id == kb.class_id)
          << "keypoint " << k;
      EXPECT_TRUE(sameBits(a.features.points[k], b.features.points[k])) << "point " << k;
    }
    EXPECT_TRUE(sameBytes(a.features.descriptors, b.features.descriptors));
    ASSERT_FALSE(a.colour.empty());
    EXPECT_TRUE(sameBytes(a.colour, b.colour));
    EXPECT_TRUE(sameBytes(a.depth, b.depth));
    EXPECT_TRUE(sameBytes(a.depthSmall, b.depthSmall));
    EXPECT_EQ(a.depthSmallStride, b.depthSmallStride);
    withImages += !b.depth.empty();
  }
  EXPECT_EQ(withImages, graph->keyframeCount());
  // The bundle adjustment's refined feature positions come back bit for bit.
  for (KeyframeId id : graph->ids()) {
    const RefinedPoints ra = graph->refinedPoints(id), rb = g2.refinedPoints(id);
    ASSERT_EQ(ra == nullptr, rb == nullptr) << "keyframe " << id;
    if (!ra) continue;
    ASSERT_EQ(ra->size(), rb->size());
    for (size_t k = 0; k < ra->size(); ++k)
      EXPECT_TRUE(sameBits((*ra)[k], (*rb)[k])) << "keyframe " << id << " point " << k;
  }

  const auto ea = graph->allEdges(), eb = g2.allEdges();
  ASSERT_EQ(ea.size(), eb.size());
  for (size_t k = 0; k < ea.size(); ++k) {
    EXPECT_EQ(ea[k].i, eb[k].i);
    EXPECT_EQ(ea[k].j, eb[k].j);
    ASSERT_EQ(ea[k].matches.size(), eb[k].matches.size());
    for (size_t m = 0; m < ea[k].matches.size(); ++m) {
      const PointMatch &pa = ea[k].matches[m], &pb = eb[k].matches[m];
      EXPECT_TRUE(sameBits(pa.pointI, pb.pointI) && sameBits(pa.pointJ, pb.pointJ) &&
                  sameBits(pa.weight, pb.weight) &&
                  sameBits(pa.information.matrix(), pb.information.matrix()) &&
                  pa.featureI == pb.featureI && pa.featureJ == pb.featureJ)
          << "edge " << ea[k].i << "-" << ea[k].j << " match " << m;
    }
  }
  // Saving the loaded map again gives the same bytes (deterministic format).
  loaded->saveToFile(dir + "/again.kfmap");
  mrpt::io::CMemoryStream m1, m2;
  mrpt::serialization::archiveFrom(m1) << map;
  mrpt::serialization::archiveFrom(m2) << *loaded;
  ASSERT_EQ(m1.getTotalBytesCount(), m2.getTotalBytesCount());
  EXPECT_EQ(std::memcmp(m1.getRawBufferData(), m2.getRawBufferData(), m1.getTotalBytesCount()), 0);
}

TEST(KeyframeGraphMap, RoundTripOfMapWithoutImagesAndEmptyMap) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_RoundTripNoImages");
  const auto stripped = withoutImages(*graph, true);
  // A keyframe far from the window keeps its descriptors as 8-bit codes, one nearer as half
  // floats: they come back as such.
  const KeyframeId far = stripped->ids().front(), near = stripped->ids().back();
  ASSERT_NE(far, near);
  ASSERT_TRUE(stripped->compactDescriptors(far));
  stripped->compactDescriptors(near, DescriptorStorage::HalfFloat);  // the map's may already be
  ASSERT_EQ(stripped->keyframe(near)->features.descriptors.type(), CV_16FC1);
  EXPECT_FALSE(stripped->compactDescriptors(far, DescriptorStorage::HalfFloat));  // codes stay
  EXPECT_FALSE(stripped->compactDescriptors(near, DescriptorStorage::HalfFloat));
  CKeyframeGraphMap(stripped).saveToFile(dir + "/noimages.kfmap");
  const auto loaded = CKeyframeGraphMap::loadFromFile(dir + "/noimages.kfmap");
  EXPECT_EQ(loaded->graph()->keyframeCount(), graph->keyframeCount());
  EXPECT_EQ(loaded->graph()->edgeCount(), graph->edgeCount());
  for (KeyframeId id : loaded->graph()->ids()) {
    EXPECT_TRUE(loaded->graph()->keyframe(id)->colour.empty());
    EXPECT_TRUE(loaded->graph()->keyframe(id)->depth.empty());
    const cv::Mat& d = loaded->graph()->keyframe(id)->features.descriptors;
    EXPECT_EQ(d.type(), stripped->keyframe(id)->features.descriptors.type()) << "keyframe " << id;
    if (id == far) EXPECT_EQ(d.type(), CV_8SC1);
    if (id == near) EXPECT_EQ(d.type(), CV_16FC1);
    EXPECT_TRUE(sameBytes(d, stripped->keyframe(id)->features.descriptors)) << "keyframe " << id;
  }
  // Images take most of the file.
  EXPECT_LT(fs::file_size(dir + "/noimages.kfmap") * 2, [&] {
    CKeyframeGraphMap(graph).saveToFile(dir + "/images.kfmap");
    return fs::file_size(dir + "/images.kfmap");
  }());

  CKeyframeGraphMap().saveToFile(dir + "/empty.kfmap");
  const auto empty = CKeyframeGraphMap::loadFromFile(dir + "/empty.kfmap");
  EXPECT_TRUE(empty->isEmpty());
}

TEST(KeyframeGraphMap, StoredUncompressedForCheckpointsReadsBackTheSame) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_Stored");
  const CKeyframeGraphMap map(graph);
  map.saveToFile(dir + "/compressed.kfmap");
  map.saveToFile(dir + "/stored.kfmap", 0);  // what live checkpoints write
  EXPECT_GT(fs::file_size(dir + "/stored.kfmap"), fs::file_size(dir + "/compressed.kfmap"));
  const auto a = CKeyframeGraphMap::loadFromFile(dir + "/compressed.kfmap");
  const auto b = CKeyframeGraphMap::loadFromFile(dir + "/stored.kfmap");
  ASSERT_EQ(a->graph()->ids(), b->graph()->ids());
  EXPECT_EQ(a->graph()->edgeCount(), b->graph()->edgeCount());
  for (KeyframeId id : a->graph()->ids()) {
    EXPECT_TRUE(sameBits(a->graph()->pose(id).matrix(), b->graph()->pose(id).matrix()));
    EXPECT_EQ(a->graph()->keyframe(id)->features.size(), b->graph()->keyframe(id)->features.size());
  }
  EXPECT_THROW(map.saveToFile(dir + "/bad.kfmap", 10), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir + "/bad.kfmap"));
}

TEST(KeyframeGraphMap, DepthIsExactWhetherQuantisedOrNot) {
  // Sensor-like depth (k millimetres, as RgbdFrame computes it) takes the 16-bit PNG path;
  // arbitrary floats (sub-unit values, NaN, negative zero) must fall back to raw bytes.
  const std::string dir = test::scratchDir("Maps_DepthEncoding");
  std::mt19937 rng(7);
  cv::Mat sensor(120, 160, CV_32F), arbitrary(120, 160, CV_32F);
  for (int r = 0; r < sensor.rows; ++r)
    for (int c = 0; c < sensor.cols; ++c) {
      sensor.at<float>(r, c) = float(rng() % 5000) * 1e-3f;
      arbitrary.at<float>(r, c) = std::uniform_real_distribution<float>(0.3f, 5.f)(rng);
    }
  arbitrary.at<float>(0, 0) = std::nanf("");
  arbitrary.at<float>(0, 1) = -0.0f;
  const auto saveOne = [&](const cv::Mat& depth, const std::string& name) {
    auto graph = std::make_shared<KeyframeGraph>();
    auto kf = std::make_shared<Keyframe>();
    kf->colour = cv::Mat(depth.rows, depth.cols, CV_8UC3, cv::Scalar(10, 20, 30));
    kf->depth = depth;
    graph->addKeyframe(kf, Pose::Identity());
    const std::string path = dir + "/" + name;
    CKeyframeGraphMap(graph).saveToFile(path);
    const auto loaded = CKeyframeGraphMap::loadFromFile(path);
    EXPECT_TRUE(sameBytes(loaded->graph()->keyframe(0)->depth, depth)) << name;
    EXPECT_TRUE(sameBytes(loaded->graph()->keyframe(0)->colour, kf->colour)) << name;
    return fs::file_size(path);
  };
  const auto quantisedSize = saveOne(sensor, "sensor.kfmap");
  const auto rawSize = saveOne(arbitrary, "arbitrary.kfmap");
  // Random floats hardly compress (about 4 bytes a pixel); 16-bit PNG is at most about 2.
  EXPECT_GT(rawSize, size_t(sensor.total()) * 3);
  EXPECT_LT(quantisedSize, size_t(sensor.total()) * 5 / 2);
}

TEST(KeyframeGraphMap, SaveIsAtomic) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_Atomic");
  const std::string path = dir + "/map.kfmap";
  CKeyframeGraphMap(graph).saveToFile(path);
  const auto before = readBytes(path);
  // A failing save (target folder does not exist) leaves no file behind...
  EXPECT_THROW(CKeyframeGraphMap(graph).saveToFile(dir + "/missing/map.kfmap"), std::exception);
  // ...and an overwrite leaves only the final file (no temporary beside it).
  CKeyframeGraphMap().saveToFile(path);
  EXPECT_NE(readBytes(path), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

// ------------------------------------------------------------------ bad input

TEST(KeyframeGraphMap, BadFilesGiveClearErrors) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_BadFiles");
  const std::string good = dir + "/good.kfmap";
  CKeyframeGraphMap(graph).saveToFile(good);

  expectLoadError(dir + "/absent.kfmap", "does not exist");

  const std::string empty = dir + "/empty.kfmap";
  writeBytes(empty, {}, false);
  expectLoadError(empty, "corrupt or truncated");

  std::mt19937 rng(42);
  std::vector<char> noise(8192);
  for (char& c : noise) c = char(rng() & 0xff);
  const std::string randomRaw = dir + "/random.kfmap";
  writeBytes(randomRaw, noise, false);
  expectLoadError(randomRaw, "corrupt or truncated");
  const std::string randomGz = dir + "/random_gz.kfmap";
  writeBytes(randomGz, noise, true);
  expectLoadError(randomGz, "corrupt or truncated");

  const auto full = readBytes(good);
  const std::string half = dir + "/half.kfmap";
  writeBytes(half, std::vector<char>(full.begin(), full.begin() + full.size() / 2), false);
  expectLoadError(half, "corrupt or truncated");

  // The uncompressed stream cut inside the keyframe data (MRPT's object header is intact).
  mrpt::io::CMemoryStream mem;
  mrpt::serialization::archiveFrom(mem) << CKeyframeGraphMap(graph);
  const char* raw = static_cast<const char*>(mem.getRawBufferData());
  const std::string cut = dir + "/cut.kfmap";
  writeBytes(cut, std::vector<char>(raw, raw + mem.getTotalBytesCount() / 3), true);
  expectLoadError(cut, "corrupt or truncated");

  // A valid MRPT file holding another kind of object.
  const std::string other = dir + "/points.kfmap";
  {
    mrpt::maps::CSimplePointsMap pts;
    pts.insertPoint(1, 2, 3);
    mrpt::io::CFileGZOutputStream f(other);
    mrpt::serialization::archiveFrom(f) << pts;
  }
  expectLoadError(other, "not a slamdunk::CKeyframeGraphMap");
}

TEST(KeyframeGraphMap, NewerClassVersionIsReportedAsSuch) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_NewerVersion");
  // MRPT writes an object as: class name, one version byte, data. Patch the byte after the
  // class name in an uncompressed stream, then compress it as saveToFile() would.
  mrpt::io::CMemoryStream mem;
  mrpt::serialization::archiveFrom(mem) << CKeyframeGraphMap(graph);
  const char* raw = static_cast<const char*>(mem.getRawBufferData());
  std::vector<char> bytes(raw, raw + mem.getTotalBytesCount());
  const std::string name = "slamdunk::CKeyframeGraphMap";
  const auto it = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
  ASSERT_NE(it, bytes.end());
  const size_t versionAt = size_t(it - bytes.begin()) + name.size();
  ASSERT_EQ(uint8_t(bytes[versionAt]), CKeyframeGraphMap::kSerializationVersion)
      << "MRPT's object header layout changed: fix this test";

  // Sanity check of the patching approach: the unpatched bytes load.
  const std::string same = dir + "/same.kfmap";
  writeBytes(same, bytes, true);
  EXPECT_EQ(CKeyframeGraphMap::loadFromFile(same)->graph()->keyframeCount(),
            graph->keyframeCount());

  // Version 1, maps written before keyframes kept 8-bit descriptors, has the same layout.
  bytes[versionAt] = char(1);
  writeBytes(same, bytes, true);
  EXPECT_EQ(CKeyframeGraphMap::loadFromFile(same)->graph()->keyframeCount(),
            graph->keyframeCount());

  bytes[versionAt] = char(CKeyframeGraphMap::kSerializationVersion + 3);
  const std::string newer = dir + "/newer.kfmap";
  writeBytes(newer, bytes, true);
  const std::string msg = expectLoadError(newer, "was written by a newer version");
  EXPECT_NE(
      msg.find("class version " + std::to_string(CKeyframeGraphMap::kSerializationVersion + 3) +
               "; this build reads up to " +
               std::to_string(CKeyframeGraphMap::kSerializationVersion) + ")"),
      std::string::npos)
      << msg;
}

// ------------------------------------------------------------------ MRPT integration

TEST(KeyframeGraphMap, PluginIsLoadableByAProgramLinkingOnlyMrpt) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_Plugin");
  const std::string path = dir + "/map.kfmap";
  CKeyframeGraphMap(graph).saveToFile(path);

  // The reader must not link any SlamDunk library, or the test would prove nothing.
  const auto ldd = test::runCommand("ldd " + q(SLAMDUNK_MAP_PLUGIN_READER));
  ASSERT_EQ(ldd.exitCode, 0) << ldd.output;
  EXPECT_EQ(ldd.output.find("slamdunk"), std::string::npos) << ldd.output;

  // Without the plug-in MRPT does not know the class.
  const auto without = test::runCommand(q(SLAMDUNK_MAP_PLUGIN_READER) + " --no-plugin " + q(path));
  EXPECT_EQ(without.exitCode, 4) << without.output;

  const auto with = test::runCommand(q(SLAMDUNK_MAP_PLUGIN_READER) + " " + q(SLAMDUNK_MAPS_PLUGIN) +
                                     " " + q(path));
  EXPECT_EQ(with.exitCode, 0) << with.output;
  EXPECT_NE(with.output.find("class: slamdunk::CKeyframeGraphMap"), std::string::npos)
      << with.output;
  EXPECT_NE(with.output.find("empty: no"), std::string::npos) << with.output;
  EXPECT_NE(with.output.find(std::to_string(graph->keyframeCount()) + " keyframes"),
            std::string::npos)
      << with.output;
}

TEST(KeyframeGraphMap, DeclarableInCMultiMetricMapIni) {
  registerKeyframeGraphMap();  // registering again is harmless
  mrpt::config::CConfigFileMemory cfg(R"(
[map]
keyframeGraphMap_count = 1
pointsMap_count = 1
[map_keyframeGraphMap_00_renderOpts]
cloud_decimation = 8
show_edges = false
)");
  mrpt::maps::TSetOfMetricMapInitializers inits;
  inits.loadFromConfigFile(cfg, "map");
  ASSERT_EQ(inits.size(), 2u);
  mrpt::maps::CMultiMetricMap multi;
  multi.setListOfMaps(inits);
  ASSERT_EQ(multi.maps.size(), 2u);
  const auto map = multi.mapByClass<CKeyframeGraphMap>();
  ASSERT_TRUE(map);
  EXPECT_TRUE(map->isEmpty());
  EXPECT_EQ(map->renderOptions.cloudDecimation, 8);
  EXPECT_FALSE(map->renderOptions.showEdges);
  EXPECT_TRUE(map->renderOptions.showFrustums);
  // Inserting observations is the SLAM system's job, not the map's.
  mrpt::obs::CObservation3DRangeScan obs;
  EXPECT_FALSE(map->insertObservation(obs));
  EXPECT_FALSE(map->canComputeObservationLikelihood(obs));

  // Without an options section the defaults apply.
  mrpt::config::CConfigFileMemory plain("[map]\nkeyframeGraphMap_count = 1\n");
  mrpt::maps::TSetOfMetricMapInitializers plainInits;
  plainInits.loadFromConfigFile(plain, "map");
  mrpt::maps::CMultiMetricMap plainMulti;
  plainMulti.setListOfMaps(plainInits);
  ASSERT_TRUE(plainMulti.mapByClass<CKeyframeGraphMap>());
  EXPECT_EQ(plainMulti.mapByClass<CKeyframeGraphMap>()->renderOptions.cloudDecimation,
            CKeyframeGraphMap::TRenderOptions().cloudDecimation);

  // The full class name works too, and a misspelled option is an error naming it.
  mrpt::config::CConfigFileMemory bad(R"(
[map]
slamdunk::CKeyframeGraphMap_count = 1
[map_slamdunk::CKeyframeGraphMap_00_renderOpts]
cloud_decimaton = 8
)");
  mrpt::maps::TSetOfMetricMapInitializers badInits;
  try {
    badInits.loadFromConfigFile(bad, "map");
    ADD_FAILURE() << "misspelled key accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cloud_decimaton"), std::string::npos) << e.what();
  }
}

TEST(KeyframeGraphMap, VisualizationHasFrustumsEdgesAndCloud) {
  REQUIRE_SWEEP_GRAPH(graph);
  CKeyframeGraphMap map(graph);
  const auto vis = map.getVisualization();
  const auto root = std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(
      findByName(*vis, "slamdunk_keyframe_graph_map"));
  ASSERT_TRUE(root);
  const auto frustums =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(findByName(*root, "keyframes"));
  ASSERT_TRUE(frustums);
  EXPECT_EQ(frustums->size(), graph->keyframeCount());
  for (const auto& f : *frustums) EXPECT_TRUE(std::dynamic_pointer_cast<mrpt::opengl::CFrustum>(f));
  const auto edges =
      std::dynamic_pointer_cast<mrpt::opengl::CSetOfLines>(findByName(*root, "edges"));
  ASSERT_TRUE(edges);
  EXPECT_EQ(edges->size(), graph->edgeCount());
  const auto cloud =
      std::dynamic_pointer_cast<mrpt::opengl::CPointCloudColoured>(findByName(*root, "points"));
  ASSERT_TRUE(cloud);
  // Dense: many more points than the features.
  size_t features = 0;
  for (KeyframeId id : graph->ids()) features += graph->keyframe(id)->features.size();
  EXPECT_GT(cloud->size(), 2 * features);

  // Viewer convention: a keyframe at optical pose T is drawn at S ⊕ T ⊕ S⁻¹ in MRPT's z-up world
  // (S: optical frame in the sensor frame), looking along +X as CFrustum does.
  const mrpt::poses::CPose3D S(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  for (KeyframeId id : graph->ids()) {
    const auto f = findByName(*frustums, "keyframe_" + std::to_string(id));
    ASSERT_TRUE(f);
    const mrpt::poses::CPose3D shown =
        mrpt::poses::CPose3D(root->getPose()) + mrpt::poses::CPose3D(f->getPose());
    const mrpt::poses::CPose3D expected = S + toCPose3D(graph->pose(id)) + (-S);
    EXPECT_TRUE(fromCPose3D(shown).isApprox(fromCPose3D(expected), 1e-6))
        << "keyframe " << id << ": shown " << shown << " expected " << expected;
  }
  // Points are in front of the first camera: +X in the viewer's world, for the most part.
  size_t ahead = 0;
  for (size_t k = 0; k < cloud->size(); ++k) {
    const auto pf = cloud->getPoint3Df(k);
    const auto p = root->getPose().composePoint(mrpt::math::TPoint3D(pf.x, pf.y, pf.z));
    ahead += p.x > 0;
  }
  EXPECT_GT(ahead, cloud->size() * 9 / 10);

  // Decimation option: every 8th pixel gives about a quarter of every 4th.
  map.renderOptions.cloudDecimation = 8;
  const auto sparse = std::dynamic_pointer_cast<mrpt::opengl::CPointCloudColoured>(
      findByName(*map.getVisualization(), "points"));
  ASSERT_TRUE(sparse);
  EXPECT_LT(sparse->size(), cloud->size() / 3);
  EXPECT_GT(sparse->size(), cloud->size() / 6);

  // Switches.
  map.renderOptions.showFrustums = false;
  map.renderOptions.showEdges = false;
  const auto bare = map.getVisualization();
  EXPECT_FALSE(findByName(*bare, "keyframes"));
  EXPECT_FALSE(findByName(*bare, "edges"));
  EXPECT_TRUE(findByName(*bare, "points"));

  // The simple points map matches the drawn cloud (8th pixels now).
  EXPECT_EQ(map.getAsSimplePointsMap()->size(), sparse->size());
}

TEST(KeyframeGraphMap, VisualizationWithoutImagesDrawsFeaturePoints) {
  REQUIRE_SWEEP_GRAPH(graph);
  const auto stripped = withoutImages(*graph, false);
  size_t features = 0;
  for (KeyframeId id : stripped->ids()) features += stripped->keyframe(id)->features.points.size();
  const auto cloud = std::dynamic_pointer_cast<mrpt::opengl::CPointCloudColoured>(
      findByName(*CKeyframeGraphMap(stripped).getVisualization(), "points"));
  ASSERT_TRUE(cloud);
  EXPECT_EQ(cloud->size(), features);
}

TEST(KeyframeGraphMap, SavesA3DScene) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_3DScene");
  CKeyframeGraphMap map(graph);
  map.saveMetricMapRepresentationToFile(dir + "/map");
  ASSERT_TRUE(fs::exists(dir + "/map.3Dscene"));
  mrpt::opengl::COpenGLScene scene;
  mrpt::io::CFileGZInputStream f(dir + "/map.3Dscene");
  mrpt::serialization::archiveFrom(f) >> scene;
  EXPECT_TRUE(scene.getByName("slamdunk_keyframe_graph_map"));
  EXPECT_NE(map.asString().find(std::to_string(graph->keyframeCount()) + " keyframes"),
            std::string::npos);
}

// ------------------------------------------------------------------ .simplemap export

TEST(SimpleMapExport, WritesKeyframesWithPosesAndObservations) {
  REQUIRE_SWEEP_GRAPH(graph);
  const std::string dir = test::scratchDir("Maps_SimpleMap");
  const std::string path = dir + "/map.simplemap";
  exportSimpleMap(*graph, path);
  ASSERT_TRUE(fs::exists(path));

  mrpt::maps::CSimpleMap sm;
  ASSERT_TRUE(sm.loadFromFile(path));
  ASSERT_EQ(sm.size(), graph->keyframeCount());
  const auto ids = graph->ids();
  for (size_t k = 0; k < sm.size(); ++k) {
    const auto [pdf, sf] = sm.get(k);
    const Pose back = fromMrptSensorWorld(fromCPose3D(pdf->getMeanVal()));
    EXPECT_LT((back.matrix() - graph->pose(ids[k]).matrix()).cwiseAbs().maxCoeff(), 1e-9);
    ASSERT_EQ(sf->size(), 1u);
    const auto obs = sf->getObservationByClass<mrpt::obs::CObservation3DRangeScan>();
    ASSERT_TRUE(obs);
    const Keyframe& kf = *graph->keyframe(ids[k]);
    EXPECT_TRUE(obs->hasRangeImage && obs->hasIntensityImage && obs->range_is_depth);
    EXPECT_TRUE(obs->doDepthAndIntensityCamerasCoincide());
    EXPECT_EQ(obs->rangeImage.rows(), kf.depth.rows);
    EXPECT_EQ(obs->rangeImage.cols(), kf.depth.cols);
    EXPECT_DOUBLE_EQ(obs->cameraParams.fx(), kf.intrinsics.fx);
    // Depth quantisation: within half a unit (0.05 mm) wherever valid and in range.
    double worst = 0;
    for (int r = 0; r < kf.depth.rows; r += 7)
      for (int c = 0; c < kf.depth.cols; c += 7) {
        const float d = kf.depth.at<float>(r, c);
        if (!(d > 0) || d >= 6.5) continue;
        worst = std::max(worst, std::abs(obs->rangeImage(r, c) * double(obs->rangeUnits) - d));
      }
    EXPECT_LE(worst, 0.5 * kSimpleMapDepthUnits + 1e-7);
    EXPECT_TRUE(sameBytes(obs->intensityImage.asCvMatRef(), kf.colour));
    // points3D for MRPT's point maps, in the sensor frame: x forward.
    ASSERT_TRUE(obs->hasPoints3D);
    ASSERT_GT(obs->points3D_x.size(), 1000u);
    EXPECT_GT(*std::min_element(obs->points3D_x.begin(), obs->points3D_x.end()), 0.0f);
  }
  // Poses in MRPT's convention, checked with MRPT's own operators: S ⊕ T ⊕ S⁻¹.
  const mrpt::poses::CPose3D S(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  for (size_t k = 0; k < sm.size(); ++k) {
    const mrpt::poses::CPose3D expected = S + toCPose3D(graph->pose(ids[k])) + (-S);
    EXPECT_TRUE(
        fromCPose3D(std::get<0>(sm.get(k))->getMeanVal()).isApprox(fromCPose3D(expected), 1e-9));
  }
  // The first keyframe is (about: local optimization may nudge it) MRPT's origin.
  EXPECT_LT(std::get<0>(sm.get(0))->getMeanVal().norm(), 0.01);
}

TEST(SimpleMapExport, ObservationsToMapBuildsAPointMap) {
  REQUIRE_SWEEP_GRAPH(graph);
  if (test::runCommand("command -v observations2map").exitCode != 0)
    SLAMDUNK_SKIP(
        "MRPT's observations2map is not installed (apt-get install mrpt-apps); "
        "the export itself is checked by WritesKeyframesWithPosesAndObservations");
  const std::string dir = test::scratchDir("Maps_Observations2Map");
  exportSimpleMap(*graph, dir + "/map.simplemap");
  {
    std::ofstream ini(dir + "/o2m.ini");
    ini << "[MappingApplication]\n"
           "pointsMap_count = 1\n"
           "[MappingApplication_pointsMap_00_insertOpts]\n"
           "minDistBetweenLaserPoints = 0.02\n";
  }
  // observations2map waits for a key at the end: feed it one.
  const auto r =
      test::runCommand("cd " + q(dir) + " && echo | observations2map o2m.ini map.simplemap out");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  // The point map is saved as text, one "x y z" line per point.
  const std::string points = dir + "/out_mrpt__maps__CSimplePointsMap_00.txt";
  ASSERT_TRUE(fs::exists(points)) << r.output;
  std::ifstream f(points);
  size_t lines = 0;
  for (std::string line; std::getline(f, line);) lines += !line.empty();
  EXPECT_GT(lines, 1000u) << r.output;
}

TEST(SimpleMapExport, NoImagesIsAClearError) {
  REQUIRE_SWEEP_GRAPH(graph);
  const auto stripped = withoutImages(*graph, false);
  const std::string dir = test::scratchDir("Maps_SimpleMapNoImages");
  try {
    exportSimpleMap(*stripped, dir + "/x.simplemap");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("keep_keyframe_images"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/x.simplemap"));
}

// ------------------------------------------------------------------ map builder

namespace {
/// One observation to the builder as MRPT's rawlog-driven apps hand it over: an empty action
/// and a sensory frame with the observation.
void feed(CSlamDunkMapBuilder& builder, const mrpt::obs::CObservation::Ptr& obs) {
  mrpt::obs::CActionCollection acts;
  mrpt::obs::CSensoryFrame sf;
  sf.insert(obs);
  builder.processActionObservation(acts, sf);
}
}  // namespace

TEST(SlamDunkMapBuilder, MatchesSlamSystemOnTheSyntheticSweep) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  CSlamDunkMapBuilder builder(optionsWithImages());
  builder.initialize();
  SlamSystem reference(optionsWithImages());
  RawlogReader reader(rawlog);
  size_t frames = 0;
  while (const auto obs = reader.next()) {
    feed(builder, obs);
    reference.process(*obs);
    if (++frames == 1) {
      // First frame: MRPT's world origin.
      EXPECT_LT(builder.getCurrentPoseEstimation()->getMeanVal().norm(), 1e-12);
    }
  }
  builder.finish();
  reference.finish();
  ASSERT_GT(frames, 100u);
  EXPECT_EQ(builder.framesProcessed(), frames);

  const Trajectory traj = reference.trajectory();
  ASSERT_FALSE(traj.empty());
  ASSERT_NE(builder.lastResult().status, TrackingStatus::Lost);
  const mrpt::poses::CPose3D mrptPose = builder.getCurrentPoseEstimation()->getMeanVal();
  const Pose optical = fromMrptSensorWorld(fromCPose3D(mrptPose));
  EXPECT_LT(translationDistance(optical, traj.back().pose), 1e-3);
  EXPECT_LT(rotationDistance(optical, traj.back().pose), 1e-3);
  // The camera moved, so the comparison means something.
  EXPECT_GT(traj.back().pose.translation().norm(), 0.05);

  EXPECT_EQ(builder.getCurrentlyBuiltMapSize(), reference.graph()->keyframeCount());
  const auto* multi = builder.getCurrentlyBuiltMetricMap();
  ASSERT_TRUE(multi);
  const auto kfMap = multi->mapByClass<CKeyframeGraphMap>();
  ASSERT_TRUE(kfMap);
  EXPECT_EQ(kfMap->graph(), builder.system().graph());
  EXPECT_FALSE(kfMap->isEmpty());

  mrpt::maps::CSimpleMap sm;
  builder.getCurrentlyBuiltMap(sm);
  EXPECT_EQ(sm.size(), builder.getCurrentlyBuiltMapSize());

  // initialize() starts over, with x0 placing the first camera.
  mrpt::poses::CPosePDFGaussian x0(mrpt::poses::CPose2D(1, 2, 0.5));
  builder.initialize(mrpt::maps::CSimpleMap(), &x0);
  EXPECT_EQ(builder.getCurrentlyBuiltMapSize(), 0u);
  const auto p0 = builder.getCurrentPoseEstimation()->getMeanVal();
  EXPECT_NEAR(p0.x(), 1, 1e-12);
  EXPECT_NEAR(p0.y(), 2, 1e-12);
  EXPECT_NEAR(p0.yaw(), 0.5, 1e-12);
  EXPECT_THROW(builder.initialize(sm), std::invalid_argument);
}

TEST(SlamDunkMapBuilder, ConventionsAgreeWithGroundTruth) {
  REQUIRE_RAWLOG(rawlog, "synthetic_sweep");
  const std::string gtPath =
      (fs::path(rawlog).parent_path() / "synthetic_sweep_groundtruth.txt").string();
  if (!fs::exists(gtPath)) SLAMDUNK_SKIP("no ground truth beside " << rawlog);
  const Trajectory gt = readTumTrajectory(gtPath);
  CSlamDunkMapBuilder builder;
  RawlogReader reader(rawlog);
  size_t frames = 0;
  double firstTimestamp = 0;
  while (const auto obs = reader.next()) {
    feed(builder, obs);
    if (frames == 0) firstTimestamp = builder.lastResult().timestamp;
    if (++frames == 60) break;
  }
  ASSERT_NE(builder.lastResult().status, TrackingStatus::Lost);
  // Ground truth of the same frame relative to the first one, expressed in MRPT's z-up
  // convention by hand: S · T · S⁻¹ with S the optical frame's pose in the sensor frame.
  const auto gtAt = [&](double t) {
    const auto it = std::min_element(gt.begin(), gt.end(), [&](const auto& a, const auto& b) {
      return std::abs(a.timestamp - t) < std::abs(b.timestamp - t);
    });
    EXPECT_LT(std::abs(it->timestamp - t), 1e-3) << "no ground truth at " << t;
    return it->pose;
  };
  const Pose rel = gtAt(firstTimestamp).inverse() * gtAt(builder.lastResult().timestamp);
  // S ⊕ rel ⊕ S⁻¹, with MRPT's operators (unary minus is the inverse pose).
  const mrpt::poses::CPose3D S(0, 0, 0, mrpt::DEG2RAD(-90.0), 0, mrpt::DEG2RAD(-90.0));
  const mrpt::poses::CPose3D expected = S + toCPose3D(rel) + (-S);
  const mrpt::poses::CPose3D got = builder.getCurrentPoseEstimation()->getMeanVal();
  EXPECT_GT(expected.norm(), 0.05) << "the sweep should have moved by frame 60";
  EXPECT_LT(translationDistance(fromCPose3D(got), fromCPose3D(expected)), 0.03)
      << "got " << got << " expected " << expected;
  EXPECT_LT(rotationDistance(fromCPose3D(got), fromCPose3D(expected)), mrpt::DEG2RAD(2.0))
      << "got " << got << " expected " << expected;
}
