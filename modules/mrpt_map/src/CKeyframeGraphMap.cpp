#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/DepthBackProjection.h>
#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/IniOptions.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>
#include <slamdunk/mrpt_map/CameraFrustum.h>

#include "KeyframeGraphCodec.h"

#include <mrpt/core/initializer.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace slamdunk {

IMPLEMENTS_SERIALIZABLE(CKeyframeGraphMap, mrpt::maps::CMetricMap, slamdunk)

// "keyframeGraphMap" is the short name for CMultiMetricMap INI files ("keyframeGraphMap_count").
MAP_DEFINITION_REGISTER("slamdunk::CKeyframeGraphMap,keyframeGraphMap", slamdunk::CKeyframeGraphMap)

// Runs when the library is loaded (also through mrpt::system::loadPluginModule): lets
// CArchive::ReadObject() create this class by name.
MRPT_INITIALIZER(slamdunk_register_CKeyframeGraphMap) {
  mrpt::rtti::registerClass(CLASS_ID(slamdunk::CKeyframeGraphMap));
}

void registerKeyframeGraphMap() {
  mrpt::rtti::registerClass(CLASS_ID(slamdunk::CKeyframeGraphMap));
}

namespace {

// serializeFrom() records a too-new version here so loadFromFile() can report it precisely even
// if MRPT wraps the exception on its way out of ReadObject().
thread_local int tooNewVersionSeen = -1;

/// Colour of keyframe k of n along a blue -> green -> red ramp (creation order).
mrpt::img::TColor rampColour(size_t k, size_t n) {
  const double t = n > 1 ? double(k) / double(n - 1) : 0.0;
  const auto u8 = [](double v) { return uint8_t(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5); };
  return {u8(2.0 * t - 1.0), u8(1.0 - std::abs(2.0 * t - 1.0)), u8(1.0 - 2.0 * t)};
}

/// Calls fn(pointInWorldOptical, r, g, b) for every point the map draws: keyframe depth
/// back-projected (every decimation-th pixel, colour from the keyframe image), or the features'
/// 3D points (coloured per keyframe) when a keyframe has no images.
template <typename Fn>
void forEachMapPoint(const KeyframeGraph& graph, const CKeyframeGraphMap::TRenderOptions& opt,
                     Fn&& fn) {
  const auto poses = graph.poses();
  size_t k = 0;
  for (const auto& [id, pose] : poses) {
    const KeyframePtr kf = graph.keyframe(id);
    const mrpt::img::TColor ramp = rampColour(k++, poses.size());
    const cv::Mat& depth = kf->depth;
    if (depth.empty() || depth.type() != CV_32F) {
      for (const Eigen::Vector3d& p : kf->features.points)
        fn(Eigen::Vector3d(pose * p), ramp.R, ramp.G, ramp.B);
      continue;
    }
    const cv::Mat& colour = kf->colour;
    const bool sameSize = colour.rows == depth.rows && colour.cols == depth.cols;
    const DepthSampling sampling{opt.cloudDecimation, 1, true};
    forEachDepthPoint(
        depth, kf->intrinsics, sampling, [&](float z) { return z > 0.0f && !(z > opt.maxDepth); },
        [&](int u, int v, const Eigen::Vector3d& p) {
          const Eigen::Vector3d world = pose * p;
          if (const auto rgb = sameSize ? rgbAt(colour, u, v) : std::nullopt)
            fn(world, (*rgb)[0], (*rgb)[1], (*rgb)[2]);
          else
            fn(world, ramp.R, ramp.G, ramp.B);
        });
  }
}

}  // namespace

// ------------------------------------------------------------------ options

void CKeyframeGraphMap::TRenderOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                                           const std::string& section) {
  loadIniKeys(*this, cfg, section);
  const SectionChecks require(section);
  require(cloudDecimation >= 1, "cloud_decimation must be >= 1");
  require(maxDepth > 0 && pointSize > 0 && frustumSize > 0,
          "max_depth, point_size and frustum_size must be > 0");
}

void CKeyframeGraphMap::TRenderOptions::saveToConfigFile(mrpt::config::CConfigFileBase& cfg,
                                                         const std::string& section) const {
  saveIniKeys(*this, cfg, section);
}

CKeyframeGraphMap::TMapDefinition::TMapDefinition() = default;

void CKeyframeGraphMap::TMapDefinition::loadFromConfigFile_map_specific(
    const mrpt::config::CConfigFileBase& source, const std::string& sectionNamePrefix) {
  renderOptions.loadFromConfigFile(source, sectionNamePrefix + "_renderOpts");
}

void CKeyframeGraphMap::TMapDefinition::dumpToTextStream_map_specific(std::ostream& out) const {
  renderOptions.dumpToTextStream(out);
}

mrpt::maps::CMetricMap* CKeyframeGraphMap::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& def) {
  const auto& d = dynamic_cast<const CKeyframeGraphMap::TMapDefinition&>(def);
  auto* map = new CKeyframeGraphMap();
  map->renderOptions = d.renderOptions;
  return map;
}

// ------------------------------------------------------------------ construction

CKeyframeGraphMap::CKeyframeGraphMap() : graph_(std::make_shared<KeyframeGraph>()) {}

CKeyframeGraphMap::CKeyframeGraphMap(std::shared_ptr<KeyframeGraph> graph)
    : graph_(graph ? std::move(graph) : std::make_shared<KeyframeGraph>()) {}

const std::shared_ptr<KeyframeGraph>& CKeyframeGraphMap::graph() const { return graph_; }

void CKeyframeGraphMap::setGraph(std::shared_ptr<KeyframeGraph> graph) {
  graph_ = graph ? std::move(graph) : std::make_shared<KeyframeGraph>();
}

// ------------------------------------------------------------------ serialization

uint8_t CKeyframeGraphMap::serializeGetVersion() const { return kSerializationVersion; }

void CKeyframeGraphMap::serializeTo(mrpt::serialization::CArchive& out) const {
  writeKeyframeGraph(out, *graph_);
}

void CKeyframeGraphMap::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version) {
  if (version > kSerializationVersion) {
    tooNewVersionSeen = version;
    MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
  }
  // A new graph swapped in only when complete: a failed read leaves the map as it was and never
  // touches a graph shared with a running SLAM system.
  graph_ = readKeyframeGraph(in, version);
  pointsCache_.reset();
}

void CKeyframeGraphMap::saveToFile(const std::string& path) const { saveToFile(path, 1); }

void CKeyframeGraphMap::saveToFile(const std::string& path, int compressionLevel) const {
  if (compressionLevel < 0 || compressionLevel > 9)
    throw std::invalid_argument("map compression level must be 0..9, not " +
                                std::to_string(compressionLevel));
  writeGzArchive(path, *this, compressionLevel);
}

std::shared_ptr<CKeyframeGraphMap> CKeyframeGraphMap::loadFromFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("map file '" + path + "' does not exist or is not a file");
  mrpt::io::CFileGZInputStream f;
  if (!f.open(path)) throw std::runtime_error("cannot open map file '" + path + "'");
  tooNewVersionSeen = -1;
  mrpt::serialization::CSerializable::Ptr obj;
  try {
    auto in = mrpt::serialization::archiveFrom(f);
    obj = in.ReadObject();
  } catch (const std::exception& e) {
    if (tooNewVersionSeen >= 0)
      throw std::runtime_error("map file '" + path +
                               "' was written by a newer version (class version " +
                               std::to_string(tooNewVersionSeen) + "; this build reads up to " +
                               std::to_string(kSerializationVersion) + ")");
    // MRPT's messages carry a banner and a stack trace per nested object: one line instead.
    throw std::runtime_error("map file '" + path + "' is corrupt or truncated (" +
                             summarizeError(e.what()) + ")");
  }
  auto map = std::dynamic_pointer_cast<CKeyframeGraphMap>(obj);
  if (!map)
    throw std::runtime_error("map file '" + path + "' holds a " +
                             std::string(obj ? obj->GetRuntimeClass()->className : "null object") +
                             ", not a slamdunk::CKeyframeGraphMap");
  return map;
}

// ------------------------------------------------------------------ CMetricMap

void CKeyframeGraphMap::internal_clear() {
  // A fresh graph rather than emptying the shared one: clearing the map must not pull the
  // ground from under a SLAM system that still uses its graph.
  graph_ = std::make_shared<KeyframeGraph>();
  pointsCache_.reset();
}

bool CKeyframeGraphMap::isEmpty() const { return graph_->keyframeCount() == 0; }

bool CKeyframeGraphMap::internal_insertObservation(
    const mrpt::obs::CObservation&, const std::optional<const mrpt::poses::CPose3D>&) {
  return false;
}

double CKeyframeGraphMap::internal_computeObservationLikelihood(const mrpt::obs::CObservation&,
                                                                const mrpt::poses::CPose3D&) const {
  return 0;
}

bool CKeyframeGraphMap::internal_canComputeObservationLikelihood(
    const mrpt::obs::CObservation&) const {
  return false;
}

std::string CKeyframeGraphMap::asString() const {
  const auto ids = graph_->ids();
  size_t withImages = 0, features = 0, matches = 0;
  for (KeyframeId id : ids) {
    const KeyframePtr kf = graph_->keyframe(id);
    withImages += !kf->depth.empty();
    features += kf->features.size();
  }
  const auto edges = graph_->allEdges();
  for (const KeyframeEdge& e : edges) matches += e.matches.size();
  std::ostringstream s;
  s << "slamdunk::CKeyframeGraphMap: " << ids.size() << " keyframes (" << withImages
    << " with images, " << features << " features), " << edges.size() << " edges, " << matches
    << " matches";
  return s.str();
}

void CKeyframeGraphMap::getVisualizationInto(mrpt::opengl::CSetOfObjects& o) const {
  // Everything below is in the graph's world (first camera's optical frame); the wrapper turns
  // it into that camera's MRPT sensor frame so viewers show the map z-up.
  auto root = mrpt::opengl::CSetOfObjects::Create();
  root->setName("slamdunk_keyframe_graph_map");
  root->setPose(toCPose3D(opticalInSensor()));

  const auto poses = graph_->poses();
  if (renderOptions.showFrustums) {
    auto frustums = mrpt::opengl::CSetOfObjects::Create();
    frustums->setName("keyframes");
    FrustumShape shape;
    shape.nearDistance = 0.01f * renderOptions.frustumSize;
    shape.farDistance = renderOptions.frustumSize;
    shape.lineWidth = 1.5f;
    size_t k = 0;
    for (const auto& [id, pose] : poses) {
      shape.setFieldOfView(graph_->keyframe(id)->intrinsics);
      shape.colour = rampColour(k++, poses.size());
      auto f = makeCameraFrustum(shape, pose);
      f->setName("keyframe_" + std::to_string(id));
      frustums->insert(f);
    }
    root->insert(frustums);
  }
  if (renderOptions.showEdges) {
    auto lines = mrpt::opengl::CSetOfLines::Create();
    lines->setName("edges");
    lines->setColor_u8(mrpt::img::TColor(255, 160, 0));
    lines->setLineWidth(1.0f);
    for (const KeyframeEdge& e : graph_->allEdges()) {
      const auto a = poses.find(e.i), b = poses.find(e.j);
      if (a == poses.end() || b == poses.end()) continue;
      const Eigen::Vector3d pa = a->second.translation(), pb = b->second.translation();
      lines->appendLine(pa.x(), pa.y(), pa.z(), pb.x(), pb.y(), pb.z());
    }
    root->insert(lines);
  }
  if (renderOptions.showPoints) {
    auto cloud = mrpt::opengl::CPointCloudColoured::Create();
    cloud->setName("points");
    cloud->setPointSize(renderOptions.pointSize);
    forEachMapPoint(*graph_, renderOptions,
                    [&](const Eigen::Vector3d& p, uint8_t r, uint8_t g, uint8_t b) {
                      cloud->push_back(float(p.x()), float(p.y()), float(p.z()), r / 255.f,
                                       g / 255.f, b / 255.f);
                    });
    root->insert(cloud);
  }
  o.insert(root);
}

void CKeyframeGraphMap::saveMetricMapRepresentationToFile(const std::string& prefix) const {
  mrpt::opengl::COpenGLScene scene;
  scene.insert(getVisualization());
  writeGzArchive(prefix + ".3Dscene", scene);
}

const mrpt::maps::CSimplePointsMap* CKeyframeGraphMap::getAsSimplePointsMap() const {
  auto pts = std::make_shared<mrpt::maps::CSimplePointsMap>();
  const Pose& S = opticalInSensor();
  forEachMapPoint(*graph_, renderOptions, [&](const Eigen::Vector3d& p, uint8_t, uint8_t, uint8_t) {
    const Eigen::Vector3d q = S * p;
    pts->insertPoint(float(q.x()), float(q.y()), float(q.z()));
  });
  pointsCache_ = std::move(pts);
  return pointsCache_.get();
}

}  // namespace slamdunk
