#include <slamdunk/viewer/LiveMapScene.h>

#include <slamdunk/core/DepthBackProjection.h>
#include <slamdunk/mrpt_map/CameraFrustum.h>

#include <mrpt/img/CImage.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/stock_objects.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace slamdunk::viewer {

namespace {

// An edge of a loop-closing keyframe to one spawned more than this many keyframes before it
// closes the loop; its edges to the keyframes just before it are the path's own.
constexpr KeyframeId kLoopIdGap = 3;

mrpt::img::TColor colour(const unsigned char (&c)[3]) {
  return mrpt::img::TColor(c[0], c[1], c[2]);
}
cv::Scalar bgr(const unsigned char (&c)[3]) { return cv::Scalar(c[2], c[1], c[0]); }

/// A frustum drawn in the optical frame of the camera or keyframe object it belongs to.
mrpt::opengl::CFrustum::Ptr frustum(float depth, const unsigned char (&c)[3], float lineWidth) {
  FrustumShape shape;
  shape.farDistance = depth;
  shape.lineWidth = lineWidth;
  shape.colour = colour(c);
  return makeCameraFrustum(shape, Pose::Identity());
}

/// Each point of a keyframe's cloud, in order: its subsampled depth's valid pixels, as (u, v)
/// in the full image and the point in the keyframe's optical frame.
template <class Point>
void forEachCloudPoint(const Keyframe& kf, const LiveMapSceneOptions& options, Point&& point) {
  cv::Mat depth;
  kf.depthSmall.convertTo(depth, CV_32F);
  forEachDepthPoint(
      depth, kf.intrinsics, DepthSampling{options.cloudStride, kf.depthSmallStride, false},
      [&](float z) { return z > 0.1f && z < options.maxDepth; }, point);
}

/// A cloud point's colour: its pixel in the keyframe's image, or without one a neutral
/// blue-grey, lighter near the camera.
mrpt::img::TColorf pointColour(const cv::Mat& image, int u, int v, float z, double maxDepth) {
  if (const auto rgb = rgbAt(image, u, v))
    return mrpt::img::TColorf((*rgb)[0] / 255.f, (*rgb)[1] / 255.f, (*rgb)[2] / 255.f);
  const float shade = 0.35f + 0.5f * (1 - z / static_cast<float>(maxDepth));
  return mrpt::img::TColorf(shade, shade, std::min(1.0f, shade + 0.15f));
}

}  // namespace

LiveMapScene::LiveMapScene(const LiveMapSceneOptions& options) : options_(options) {
  using namespace mrpt::opengl;
  map_ = CSetOfObjects::Create();
  map_->setName("slamdunk_live_map");
  // Everything below lives in the map's world (optical, y down); shown z-up like
  // CKeyframeGraphMap does (the first camera's MRPT sensor frame).
  map_->setPose(toCPose3D(opticalInSensor()));
  keyframes_ = CSetOfObjects::Create();
  edges_ = CSetOfLines::Create();
  edges_->setColor_u8(colour(kEdge));
  edges_->setLineWidth(1);
  loopEdges_ = CSetOfLines::Create();
  loopEdges_->setColor_u8(colour(kLoopEdge));
  loopEdges_->setLineWidth(3);
  trajectory_ = CSetOfLines::Create();
  trajectory_->setColor_u8(colour(kTrajectory));
  trajectory_->setLineWidth(2);
  camera_ = CSetOfObjects::Create();
  camera_->insert(frustum(0.2f, kCamera, 3));
  camera_->setVisibility(false);
  for (const auto& o :
       {CRenderizable::Ptr(keyframes_), CRenderizable::Ptr(edges_), CRenderizable::Ptr(loopEdges_),
        CRenderizable::Ptr(trajectory_), CRenderizable::Ptr(camera_)})
    map_->insert(o);
}

void LiveMapScene::attachTo(mrpt::opengl::COpenGLScene& scene) {
  mainViewport_ = scene.getViewport("main");
  mainViewport_->setCustomBackgroundColor(mrpt::img::TColorf(0.12f, 0.12f, 0.14f));
  scene.insert(mrpt::opengl::stock_objects::CornerXYZSimple(0.2f, 2));
  scene.insert(map_);
  imageViewport_ = scene.createViewport("camera_image");
  const double w = options_.imageViewportWidth;
  const double h = std::min(1.0, w * options_.windowAspect * 3.0 / 4.0);  // 4:3 until a frame
  imageViewport_->setViewportPosition(0, 1 - h, w, h);
  imageViewport_->setBorderSize(1);
}

void LiveMapScene::addFrame(const FrameRecord& record) { frames_.push_back(record); }

void LiveMapScene::setKeyframeColour(KeyframeId id, const cv::Mat& colour) {
  // Taken by the next update(): for a keyframe not drawn yet, or one drawn before its image
  // came (see update()).
  keyframeColours_[id] = colour;
}

void LiveMapScene::markLoopClosure(KeyframeId id) {
  if (loopClosures_.insert(id).second) edgeCount_ = static_cast<size_t>(-1);  // redraw edges
}

mrpt::opengl::CSetOfObjects::Ptr LiveMapScene::makeKeyframe(const Keyframe& kf) const {
  auto group = mrpt::opengl::CSetOfObjects::Create();
  group->insert(frustum(0.08f, kFrustum, 1));
  if (kf.depthSmall.empty() || !options_.showCloud) return group;
  // The cloud: the keyframe's subsampled depth (kept in every map), coloured by its image.
  cv::Mat image = kf.colour;
  if (const auto it = keyframeColours_.find(kf.id); image.empty() && it != keyframeColours_.end())
    image = it->second;
  auto cloud = mrpt::opengl::CPointCloudColoured::Create();
  const int step = std::max(1, options_.cloudStride);
  cloud->reserve(static_cast<size_t>(kf.depthSmall.rows / step + 1) *
                 (kf.depthSmall.cols / step + 1));
  forEachCloudPoint(kf, options_, [&](int u, int v, const Eigen::Vector3d& p) {
    const mrpt::img::TColorf c = pointColour(image, u, v, float(p.z()), options_.maxDepth);
    cloud->push_back(float(p.x()), float(p.y()), float(p.z()), c.R, c.G, c.B);
  });
  cloud->setPointSize(options_.pointSize);
  group->insert(cloud);
  return group;
}

void LiveMapScene::update(const KeyframeGraph& graph, const ViewerFrame* latest,
                          const ViewerStatus& status) {
  const auto poses = graph.poses();
  // Keyframes: new ones built once, every one moved to its current (optimized) pose.
  for (const auto& [id, pose] : poses) {
    auto it = keyframeObjects_.find(id);
    if (it == keyframeObjects_.end()) {
      const KeyframePtr kf = graph.keyframe(id);
      if (!kf) continue;
      it = keyframeObjects_.emplace(id, makeKeyframe(*kf)).first;
      keyframeColours_.erase(id);
      keyframes_->insert(it->second);
    } else if (const auto colour = keyframeColours_.find(id); colour != keyframeColours_.end()) {
      // The graph has a keyframe as soon as tracking made it, its image comes with its frame's
      // batch, later (a frame later when the viewer was taking the previous batch): drawn
      // meanwhile in the neutral colour, its cloud is coloured now, in place (a busy machine
      // left most of a live session's cloud grey).
      if (const KeyframePtr kf = graph.keyframe(id); kf && kf->colour.empty()) {
        if (const auto cloud = it->second->getByClass<mrpt::opengl::CPointCloudColoured>()) {
          size_t i = 0;
          forEachCloudPoint(*kf, options_, [&](int u, int v, const Eigen::Vector3d& p) {
            if (i >= cloud->size()) return;
            const mrpt::img::TColorf c =
                pointColour(colour->second, u, v, float(p.z()), options_.maxDepth);
            cloud->setPointColor_fast(i++, c.R, c.G, c.B);
          });
          cloud->markAllPointsAsNew();
        }
      }
      keyframeColours_.erase(colour);
    }
    it->second->setPose(toCPose3D(pose));
  }
  for (auto it = keyframeObjects_.begin(); it != keyframeObjects_.end();) {
    if (poses.count(it->first)) {
      ++it;
      continue;
    }
    keyframes_->removeObject(it->second);  // culled as redundant
    keyframeColours_.erase(it->first);
    it = keyframeObjects_.erase(it);
  }

  // Graph edges between keyframe centres; loop closures in their own colour.
  if (const size_t n = graph.edgeCount(); n != edgeCount_) {
    edgeIds_ = graph.edgeIds();
    edgeCount_ = n;
  }
  edges_->clear();
  loopEdges_->clear();
  for (const auto& [i, j] : edgeIds_) {
    const auto a = poses.find(i), b = poses.find(j);
    if (a == poses.end() || b == poses.end()) continue;
    const Eigen::Vector3d p = a->second.translation(), q = b->second.translation();
    const bool loop = loopClosures_.count(j) && j > i + kLoopIdGap;
    (loop ? loopEdges_ : edges_)->appendLine(p.x(), p.y(), p.z(), q.x(), q.y(), q.z());
  }

  // The trajectory through the keyframes' current poses (decimated when very long).
  trajectory_->clear();
  const size_t stride = frames_.size() / std::max<size_t>(1, options_.maxTrajectorySegments) + 1;
  bool havePrevious = false;
  Eigen::Vector3d previous;
  for (size_t k = 0; k < frames_.size(); k += stride) {
    const FrameRecord& f = frames_[k];
    if (f.status == TrackingStatus::Lost) continue;
    const std::optional<Pose> reference = graph.findPose(f.reference);  // culled: its successor
    if (!reference) continue;
    const Eigen::Vector3d p = (*reference * f.poseInReference).translation();
    if (havePrevious)
      trajectory_->appendLine(previous.x(), previous.y(), previous.z(), p.x(), p.y(), p.z());
    previous = p;
    havePrevious = true;
  }

  if (latest) {
    camera_->setVisibility(true);
    camera_->setPose(toCPose3D(latest->pose));
    const bool lost = latest->status == TrackingStatus::Lost;
    if (lost != cameraLost_) {
      cameraLost_ = lost;
      camera_->clear();
      camera_->insert(frustum(0.2f, lost ? kCameraLost : kCamera, 3));
    }
    cameraPosition_ = opticalInSensor() * latest->pose.translation();
    if (latest->index != imageFrame_ && !latest->colour.empty()) updateImage(*latest);
  }

  if (mainViewport_) {
    mrpt::opengl::TFontParams font;
    font.vfont_scale = 12;
    font.draw_shadow = true;
    mainViewport_->addTextMessage(8, 8, statusLine(latest, status), 0, font);
    font.color = mrpt::img::TColorf(1.0f, 0.85f, 0.3f);
    mainViewport_->addTextMessage(8, 26, status.note, 1, font);
  }
}

void LiveMapScene::updateImage(const ViewerFrame& frame) {
  imageFrame_ = frame.index;
  if (!imageViewport_) return;
  cv::Mat small;
  const double scale = double(options_.imageWidth) / frame.colour.cols;
  cv::resize(frame.colour, small, cv::Size(), scale, scale, cv::INTER_AREA);
  if (small.channels() == 1) cv::cvtColor(small, small, cv::COLOR_GRAY2BGR);
  for (const auto& p : frame.rejected)
    cv::circle(small, p * scale, 2, bgr(kRejected), 1, cv::LINE_AA);
  for (const auto& p : frame.inliers) cv::circle(small, p * scale, 2, bgr(kInlier), 1, cv::LINE_AA);
  // The viewport takes the image's proportions (set once: frames keep their size).
  double x, y, w, h;
  imageViewport_->getViewportPosition(x, y, w, h);
  const double wanted =
      std::min(1.0, w * options_.windowAspect * double(small.rows) / double(small.cols));
  if (std::abs(wanted - h) > 1e-6) imageViewport_->setViewportPosition(0, 1 - wanted, w, wanted);
  imageViewport_->setImageView(mrpt::img::CImage(small, mrpt::img::SHALLOW_COPY));
}

std::string LiveMapScene::statusLine(const ViewerFrame* latest, const ViewerStatus& s) {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "frame %zu  %.1f fps  %s  keyframes %zu  loops %zu  lost %zu  dropped %zu",
                s.frames, s.fps, latest ? toString(latest->status) : "waiting", s.keyframes,
                s.loopClosures, s.lost, s.dropped);
  return buf;
}

}  // namespace slamdunk::viewer
