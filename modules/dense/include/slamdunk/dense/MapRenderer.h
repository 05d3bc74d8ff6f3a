#pragma once
// Pictures of a map without a display: an MRPT 3D scene (coloured dense cloud, keyframe
// frustums, graph edges, trajectory) shown z-up, framed so the whole map fits, rendered offscreen
// (CFBORender, EGL) to a PNG, and savable as a .3Dscene file for SceneViewer3D.

#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/dense/DenseCloud.h>
#include <slamdunk/dense/DenseReconstruction.h>
#include <slamdunk/graph/KeyframeGraph.h>

#include <Eigen/Core>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mrpt::opengl {
class COpenGLScene;
}

namespace slamdunk {

struct RenderOptions {
  int width = 1024, height = 768;  ///< pixels
  double azimuthDeg = 210;         ///< around the vertical axis; 180 = from behind the first camera
  double elevationDeg = 35;        ///< above the horizontal plane
  double distance = 0;             ///< metres from the map centre; 0 = fit the whole map in view
  double fovDeg = 45;              ///< vertical field of view
  double pointSize = 2;            ///< pixels
  bool showFrustums = true, showEdges = true, showTrajectory = true;
  /// Estimate "up" from the cameras (see worldToDisplay()) instead of taking the first camera's.
  bool levelWithCameras = true;

  /// Throws std::invalid_argument naming the bad value.
  void validate() const;
};

/// Where the default camera looks from: everything in the display (z-up) frame.
struct RenderView {
  Pose worldToDisplay = Pose::Identity();
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  Eigen::Vector3f boxMin = Eigen::Vector3f::Zero(), boxMax = Eigen::Vector3f::Zero();
  double distance = 1, azimuthDeg = 0, elevationDeg = 0;
};

class MapRenderer {
 public:
  explicit MapRenderer(const RenderOptions& options = {});

  /// Map contents, all in the map's world frame (first camera's optical frame, y down).
  void setCloud(DenseCloud cloud) { cloud_ = std::move(cloud); }
  void setKeyframePoses(std::vector<Pose> poses) { keyframes_ = std::move(poses); }
  void setEdges(std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> edges) {
    edges_ = std::move(edges);
  }
  void setTrajectory(const Trajectory& trajectory);
  /// Keyframe poses and edges of a graph (not its cloud: see buildDenseCloud / setCloud).
  void setGraph(const KeyframeGraph& graph);

  /// The camera the scene will be seen from (options, or the automatic framing).
  RenderView view() const;
  std::shared_ptr<mrpt::opengl::COpenGLScene> buildScene() const;

  /// Renders offscreen to a PNG of options.width x options.height, atomically. Throws
  /// std::runtime_error (no OpenGL context, unwritable file).
  void renderPng(const mrpt::opengl::COpenGLScene& scene, const std::string& pngPath) const;

  /// .3Dscene: gz-compressed serialized COpenGLScene (SceneViewer3D), written atomically.
  static void saveScene(const mrpt::opengl::COpenGLScene& scene, const std::string& path);
  /// Throws std::runtime_error naming the file when it is missing or not a scene.
  static std::shared_ptr<mrpt::opengl::COpenGLScene> loadScene(const std::string& path);

  /// Rotation from the map world (first camera's optical frame, y down) to the display frame:
  /// z up, x along the first camera's view projected on the ground. Without cameras (or with
  /// levelWithCameras off) this is opticalInSensor(). Otherwise "up" is the direction most
  /// orthogonal to all cameras' x (right) axes, which stay nearly horizontal for a handheld or
  /// robot camera that pitches and pans, signed like their mean up vector; when the cameras
  /// do not pan enough to tell, their mean up vector itself.
  Pose worldToDisplay() const;

 private:
  RenderOptions options_;
  DenseCloud cloud_;
  std::vector<Pose> keyframes_;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> edges_;
  std::vector<Pose> trajectory_;
};

struct MapRenderSummary {
  size_t cloudPoints = 0, keyframes = 0;
  bool denseCloud = false;  ///< false: feature points (the map kept no images)
  double renderSeconds = 0;
};

/// One call for applications: renders a graph (dense cloud from the keyframes that kept images,
/// else their feature points; frustums; edges; the trajectory if not empty) to pngPath, and
/// saves the scene to scenePath unless it is empty. Throws on bad options or unwritable files.
MapRenderSummary renderKeyframeGraph(const KeyframeGraph& graph, const Trajectory& trajectory,
                                     const std::string& pngPath, const std::string& scenePath = {},
                                     const RenderOptions& render = {},
                                     const DenseOptions& cloud = {});

}  // namespace slamdunk
