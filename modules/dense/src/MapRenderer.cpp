#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/mrpt_map/CameraFrustum.h>

#include <mrpt/img/CImage.h>

#include <Eigen/Eigenvalues>

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/stock_objects.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// The distance at which a box (corners relative to the pointed-at centre) fits the view.
double fittingDistance(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                       const Eigen::Vector3f& centre, double azimuthDeg, double elevationDeg,
                       double halfFovV, double halfFovH) {
  const double az = azimuthDeg * kPi / 180, el = elevationDeg * kPi / 180;
  // MRPT's orbit camera sits at centre + d * back, looking at the centre, z up.
  const Eigen::Vector3d back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                             std::sin(el));
  Eigen::Vector3d right = (-back).cross(Eigen::Vector3d::UnitZ());
  if (right.norm() < 1e-6) right = Eigen::Vector3d(-std::sin(az), std::cos(az), 0);
  right.normalize();
  const Eigen::Vector3d up = right.cross(-back);
  double d = 0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3f c((k & 1 ? hi : lo).x(), (k & 2 ? hi : lo).y(), (k & 4 ? hi : lo).z());
    const Eigen::Vector3d p = (c - centre).cast<double>();
    // In front of the eye by d - p.back; its offsets must stay within the half fields of view.
    d = std::max(d, p.dot(back) + std::abs(p.dot(right)) / std::tan(halfFovH));
    d = std::max(d, p.dot(back) + std::abs(p.dot(up)) / std::tan(halfFovV));
  }
  return d;
}

}  // namespace

void RenderOptions::validate() const {
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    throw std::invalid_argument("image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is out of range (16..8192 pixels)");
  if (!std::isfinite(azimuthDeg) || !std::isfinite(elevationDeg) || elevationDeg < -90 ||
      elevationDeg > 90)
    throw std::invalid_argument("elevation must be within [-90, 90] degrees, azimuth finite");
  if (!(distance >= 0) || !std::isfinite(distance))
    throw std::invalid_argument("distance must be >= 0 metres (0 = automatic), not " +
                                std::to_string(distance));
  if (!(fovDeg > 1 && fovDeg < 170))
    throw std::invalid_argument("field of view must be within (1, 170) degrees");
  if (!(pointSize > 0 && pointSize <= 64))
    throw std::invalid_argument("point size must be within (0, 64] pixels");
}

MapRenderer::MapRenderer(const RenderOptions& options) : options_(options) { options_.validate(); }

void MapRenderer::setTrajectory(const Trajectory& trajectory) {
  trajectory_.clear();
  for (const auto& s : trajectory) trajectory_.push_back(s.pose);
}

Pose MapRenderer::worldToDisplay() const {
  const std::vector<Pose>& cameras = keyframes_.empty() ? trajectory_ : keyframes_;
  if (!options_.levelWithCameras || cameras.empty()) return opticalInSensor();
  Eigen::Vector3d meanUp = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rightScatter = Eigen::Matrix3d::Zero();
  for (const Pose& T : cameras) {
    meanUp -= T.linear().col(1);  // optical y points down
    rightScatter += T.linear().col(0) * T.linear().col(0).transpose();
  }
  if (meanUp.norm() < 1e-6) return opticalInSensor();  // cameras upside down both ways
  meanUp.normalize();
  Eigen::Vector3d up = meanUp;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(rightScatter);
  // Enough pan (the right axes span a plane) and the normal agrees with the cameras' up within
  // 45 degrees: trust it. Otherwise (a camera that never turned) the mean up is all we have.
  if (eig.eigenvalues()[1] > 0.02 * double(cameras.size())) {
    Eigen::Vector3d normal = eig.eigenvectors().col(0);
    if (normal.dot(meanUp) < 0) normal = -normal;
    if (normal.dot(meanUp) > std::cos(kPi / 4)) up = normal;
  }
  // x: the first camera's view direction laid on the ground (or its right axis turned, if it
  // looks straight up or down).
  const Eigen::Matrix3d R0 = cameras.front().linear();
  Eigen::Vector3d x = R0.col(2) - R0.col(2).dot(up) * up;
  if (x.norm() < 1e-3) x = up.cross(R0.col(0));
  x.normalize();
  Pose T = Pose::Identity();
  T.linear().row(0) = x.transpose();
  T.linear().row(1) = up.cross(x).transpose();
  T.linear().row(2) = up.transpose();
  return T;
}

void MapRenderer::setGraph(const KeyframeGraph& graph) {
  keyframes_.clear();
  edges_.clear();
  const auto poses = graph.poses();
  for (const auto& [id, pose] : poses) keyframes_.push_back(pose);
  for (const auto& e : graph.allEdges()) {
    const auto a = poses.find(e.i), b = poses.find(e.j);
    if (a != poses.end() && b != poses.end())
      edges_.emplace_back(a->second.translation(), b->second.translation());
  }
}

RenderView MapRenderer::view() const {
  RenderView v;
  v.worldToDisplay = worldToDisplay();
  const auto toDisplay = [&](const Eigen::Vector3d& p) -> Eigen::Vector3f {
    return (v.worldToDisplay * p).cast<float>();
  };
  // Box of everything shown, in the display frame: the cloud without its 1% outliers on each
  // side (a stray far reading would otherwise shrink the map to a dot), plus keyframes.
  bool any = false;
  Eigen::Vector3f lo, hi;
  if (!cloud_.empty()) {
    DenseCloud displayed;
    displayed.points.reserve(cloud_.size());
    for (const auto& p : cloud_.points) displayed.points.push_back(toDisplay(p.cast<double>()));
    const double q = cloud_.size() > 1000 ? 0.01 : 0.0;
    displayed.boundingBox(lo, hi, q, 1 - q);
    any = true;
  }
  auto grow = [&](const Eigen::Vector3d& w) {
    const Eigen::Vector3f p = toDisplay(w);
    if (!any) lo = hi = p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    any = true;
  };
  for (const auto& k : keyframes_) grow(k.translation());
  for (const auto& t : trajectory_) grow(t.translation());
  if (!any) lo = hi = Eigen::Vector3f::Zero();

  v.boxMin = lo;
  v.boxMax = hi;
  v.centre = (lo + hi) / 2;
  v.azimuthDeg = options_.azimuthDeg;
  v.elevationDeg = options_.elevationDeg;
  if (options_.distance > 0) {
    v.distance = options_.distance;
  } else {
    const double halfV = options_.fovDeg / 2 * kPi / 180;
    const double halfH = std::atan(std::tan(halfV) * options_.width / options_.height);
    const double extent = std::max(0.25, double((hi - lo).norm()));
    // A small margin around the map, and never closer than a tenth of its size.
    v.distance = std::max(0.1 * extent, 1.05 * fittingDistance(lo, hi, v.centre, v.azimuthDeg,
                                                               v.elevationDeg, halfV, halfH));
  }
  return v;
}

std::shared_ptr<mrpt::opengl::COpenGLScene> MapRenderer::buildScene() const {
  using namespace mrpt::opengl;
  auto scene = std::make_shared<COpenGLScene>();
  auto viewport = scene->getViewport("main");
  viewport->setCustomBackgroundColor(mrpt::img::TColorf(0.12f, 0.12f, 0.14f));

  const RenderView v = view();
  const double extent = std::max(0.25f, (v.boxMax - v.boxMin).norm());
  viewport->setViewportClipDistances(float(std::max(0.01, v.distance / 1000)),
                                     float(v.distance + 4 * extent));
  CCamera& cam = viewport->getCamera();
  cam.setProjectiveModel(true);
  cam.setProjectiveFOVdeg(float(options_.fovDeg));
  cam.setPointingAt(v.centre.x(), v.centre.y(), v.centre.z());
  cam.setZoomDistance(float(v.distance));
  cam.setAzimuthDegrees(float(v.azimuthDeg));
  cam.setElevationDegrees(float(v.elevationDeg));

  // Every map object lives in the map world (optical, y down); this group shows it z-up.
  auto map = CSetOfObjects::Create();
  map->setName("slamdunk_map");
  map->setPose(toCPose3D(v.worldToDisplay));

  if (!cloud_.empty()) {
    auto cloud = CPointCloudColoured::Create();
    cloud->setName("dense_cloud");
    cloud->reserve(cloud_.size());
    for (size_t i = 0; i < cloud_.size(); ++i) {
      const auto& p = cloud_.points[i];
      const auto& c = cloud_.colours[i];
      cloud->push_back(p.x(), p.y(), p.z(), c[0] / 255.f, c[1] / 255.f, c[2] / 255.f);
    }
    cloud->setPointSize(float(options_.pointSize));
    map->insert(cloud);
  }

  if (options_.showEdges && !edges_.empty()) {
    auto lines = CSetOfLines::Create();
    lines->setName("graph_edges");
    for (const auto& [a, b] : edges_) lines->appendLine(a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
    lines->setColor_u8(mrpt::img::TColor(90, 200, 90));
    lines->setLineWidth(1);
    map->insert(lines);
  }

  if (options_.showTrajectory && trajectory_.size() >= 2) {
    auto lines = CSetOfLines::Create();
    lines->setName("trajectory");
    for (size_t i = 1; i < trajectory_.size(); ++i) {
      const Eigen::Vector3d a = trajectory_[i - 1].translation(), b = trajectory_[i].translation();
      lines->appendLine(a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
    }
    lines->setColor_u8(mrpt::img::TColor(230, 60, 60));
    lines->setLineWidth(2);
    map->insert(lines);
  }

  if (options_.showFrustums) {
    // Frustums scaled to the map: visible in a room, not a wall of lines in a small scan.
    FrustumShape shape;
    shape.farDistance = float(std::clamp(0.04 * extent, 0.03, 0.4));
    shape.colour = mrpt::img::TColor(255, 170, 40);
    auto frustums = CSetOfObjects::Create();
    frustums->setName("keyframes");
    for (const Pose& T : keyframes_) frustums->insert(makeCameraFrustum(shape, T));
    map->insert(frustums);
  }
  auto origin = stock_objects::CornerXYZSimple(float(std::clamp(0.05 * extent, 0.05, 0.5)), 2);
  origin->setName("world_origin");
  map->insert(origin);

  scene->insert(map);
  return scene;
}

MapRenderSummary renderKeyframeGraph(const KeyframeGraph& graph, const Trajectory& trajectory,
                                     const std::string& pngPath, const std::string& scenePath,
                                     const RenderOptions& render, const DenseOptions& cloud) {
  const auto t0 = std::chrono::steady_clock::now();
  MapRenderer renderer(render);
  MapRenderSummary summary;
  const auto keyframes = keyframesWithImages(graph);
  summary.denseCloud = !keyframes.empty();
  DenseCloud points =
      summary.denseCloud ? buildDenseCloud(keyframes, cloud) : buildFeatureCloud(graph);
  summary.cloudPoints = points.size();
  renderer.setCloud(std::move(points));
  renderer.setGraph(graph);
  summary.keyframes = graph.keyframeCount();
  renderer.setTrajectory(trajectory);
  const auto scene = renderer.buildScene();
  renderer.renderPng(*scene, pngPath);
  if (!scenePath.empty()) MapRenderer::saveScene(*scene, scenePath);
  summary.renderSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

void MapRenderer::renderPng(const mrpt::opengl::COpenGLScene& scene,
                            const std::string& pngPath) const {
  mrpt::img::CImage image;
  try {
    mrpt::opengl::CFBORender fbo(unsigned(options_.width), unsigned(options_.height));
    fbo.setCamera(scene, scene.getViewport("main")->getCamera());
    fbo.render_RGB(scene, image);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("offscreen rendering failed (no OpenGL/EGL context?): ") +
                             e.what());
  }
  const cv::Mat& bgr = image.asCvMatRef();
  if (bgr.cols != options_.width || bgr.rows != options_.height)
    throw std::runtime_error("offscreen rendering returned a " + std::to_string(bgr.cols) + "x" +
                             std::to_string(bgr.rows) + " image");
  // Encoded in memory: the temporary file's name has no ".png" for imwrite to go by.
  std::vector<uchar> png;
  if (!cv::imencode(".png", bgr, png)) throw std::runtime_error("cannot encode '" + pngPath + "'");
  AtomicOutput out(pngPath);
  {
    std::ofstream f(out.tempPath(), std::ios::binary);
    f.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
    f.close();  // the last buffered bytes may fail too
    if (!f) throw std::runtime_error("cannot write '" + pngPath + "'");
  }
  out.commit();
}

void MapRenderer::saveScene(const mrpt::opengl::COpenGLScene& scene, const std::string& path) {
  writeGzArchive(path, scene);
}

std::shared_ptr<mrpt::opengl::COpenGLScene> MapRenderer::loadScene(const std::string& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error("scene file '" + path + "' not found");
  auto scene = std::make_shared<mrpt::opengl::COpenGLScene>();
  try {
    mrpt::io::CFileGZInputStream f;
    if (!f.open(path)) throw std::runtime_error("cannot open");
    auto archive = mrpt::serialization::archiveFrom(f);
    archive >> *scene;
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + path + "' is not a readable .3Dscene file: " + e.what());
  }
  return scene;
}

}  // namespace slamdunk
