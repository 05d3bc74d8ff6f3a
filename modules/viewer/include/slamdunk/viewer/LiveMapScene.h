#pragma once
// What the live viewer draws, as MRPT opengl objects, kept apart from the window and its thread
// so it can be rendered offscreen too: the keyframe map (a coloured cloud per keyframe from its
// subsampled depth, keyframe frustums, graph edges with loop-closure edges highlighted), the
// trajectory, the current camera, the current colour image with its features (RANSAC inliers
// green, rejected matches red) in a corner, and a status line. Everything is in the display
// frame: the map's world (first camera's optical frame) turned z-up, as CKeyframeGraphMap shows
// it. Not thread-safe: the viewer calls it on its own thread with the scene locked.

#include <slamdunk/core/CameraIntrinsics.h>
#include <slamdunk/graph/KeyframeGraph.h>
#include <slamdunk/slam/SlamSystem.h>

#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <opencv2/core.hpp>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace slamdunk::viewer {

/// The latest frame, as the tracking thread handed it over (its image shared, not copied).
struct ViewerFrame {
  size_t index = 0;
  double timestamp = 0;
  TrackingStatus status = TrackingStatus::Lost;
  Pose pose = Pose::Identity();  ///< T_world_optical; the last good pose while lost
  cv::Mat colour;                ///< BGR (or grey) image of the frame; may be empty
  std::vector<cv::Point2f> inliers, rejected;
};

/// The status line's figures.
struct ViewerStatus {
  double fps = 0;  ///< frames processed per second, over the last second or so
  size_t frames = 0, keyframes = 0, lost = 0, dropped = 0, loopClosures = 0;
  std::string note;  ///< e.g. how to resume when paused
};

struct LiveMapSceneOptions {
  /// Every n-th sample of a keyframe's subsampled depth in each axis (3: 53x40 = 2100 points
  /// for VGA at stride 4): enough to see the map, and cheap for a software renderer.
  int cloudStride = 3;
  bool showCloud = true;
  float maxDepth = 4.0f;  ///< metres; farther (noisier) depth is not drawn
  float pointSize = 2.0f;
  int imageWidth = 320;             ///< pixels of the image shown in the corner
  double imageViewportWidth = 0.3;  ///< fraction of the window's width
  double windowAspect = 1024.0 / 640.0;
  size_t maxTrajectorySegments = 20000;  ///< longer trajectories are drawn decimated
};

class LiveMapScene {
 public:
  explicit LiveMapScene(const LiveMapSceneOptions& options = {});

  /// Adds the objects to a scene: the map to its main viewport (dark background), the image
  /// to a new viewport "camera_image" in the top-left corner. Once, before update().
  void attachTo(mrpt::opengl::COpenGLScene& scene);

  /// Every processed frame's record, in order (the trajectory is drawn through its keyframes'
  /// current poses, so optimizations move it).
  void addFrame(const FrameRecord& record);
  /// The colour image a keyframe was made from, to colour its cloud (keyframes without one are
  /// drawn in a neutral colour, by depth).
  void setKeyframeColour(KeyframeId id, const cv::Mat& colour);
  /// A keyframe spawned by a loop closure: its edges to older keyframes are highlighted.
  void markLoopClosure(KeyframeId id);

  /// Brings every object up to date with the graph (new keyframes, moved poses, new edges),
  /// the latest frame (may be null) and the status.
  void update(const KeyframeGraph& graph, const ViewerFrame* latest, const ViewerStatus& status);

  /// Hides the map (its cloud is most of the drawing work): the window's last repaint before
  /// it closes is then cheap even for a renderer at the lowest priority on a busy machine.
  void hideMap() { map_->setVisibility(false); }

  /// The current camera's position in the display frame (for a view that follows it).
  Eigen::Vector3d cameraPosition() const { return cameraPosition_; }
  /// The status line as drawn.
  static std::string statusLine(const ViewerFrame* latest, const ViewerStatus& status);

  /// Colours, also used by the tests that look for them on the screen.
  static constexpr unsigned char kFrustum[3] = {255, 170, 40};    ///< keyframes: orange
  static constexpr unsigned char kEdge[3] = {90, 200, 90};        ///< graph edges: green
  static constexpr unsigned char kLoopEdge[3] = {255, 40, 220};   ///< loop closures: magenta
  static constexpr unsigned char kTrajectory[3] = {230, 60, 60};  ///< trajectory: red
  static constexpr unsigned char kCamera[3] = {0, 210, 255};      ///< current camera: cyan
  static constexpr unsigned char kCameraLost[3] = {255, 30, 30};  ///< current camera when lost
  static constexpr unsigned char kInlier[3] = {40, 255, 40};      ///< image: RANSAC inliers
  static constexpr unsigned char kRejected[3] = {255, 40, 40};    ///< image: rejected matches

 private:
  mrpt::opengl::CSetOfObjects::Ptr makeKeyframe(const Keyframe& keyframe) const;
  void updateImage(const ViewerFrame& frame);

  LiveMapSceneOptions options_;
  mrpt::opengl::COpenGLViewport::Ptr mainViewport_, imageViewport_;
  mrpt::opengl::CSetOfObjects::Ptr map_, keyframes_, camera_;
  mrpt::opengl::CSetOfLines::Ptr edges_, loopEdges_, trajectory_;
  std::map<KeyframeId, mrpt::opengl::CSetOfObjects::Ptr> keyframeObjects_;
  std::map<KeyframeId, cv::Mat> keyframeColours_;  ///< until the keyframe's cloud is built
  std::set<KeyframeId> loopClosures_;
  std::vector<FrameRecord> frames_;
  size_t edgeCount_ = static_cast<size_t>(-1);
  std::vector<std::pair<KeyframeId, KeyframeId>> edgeIds_;
  Eigen::Vector3d cameraPosition_ = Eigen::Vector3d::Zero();
  size_t imageFrame_ = static_cast<size_t>(-1);  ///< index of the frame whose image is shown
  bool cameraLost_ = false;
};

}  // namespace slamdunk::viewer
