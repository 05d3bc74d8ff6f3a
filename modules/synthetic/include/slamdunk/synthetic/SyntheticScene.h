#pragma once
// A textured indoor environment for synthetic RGB-D sequences: a FloorPlan (the single "room",
// or the "office" of four rooms and corridors) turned into an MRPT scene. Every surface carries
// its own procedural texture, generated deterministically from a seed: dense, high-contrast
// detail at several scales and never repeated, so feature detectors find many distinctive
// keypoints everywhere and matches are never ambiguous.
//
// World frame: gravity aligned like a level optical frame, y points DOWN; the floor is the plane
// y = floorY and the ground-parallel coordinates are x and z (see FloorPlan.h).

#include <slamdunk/synthetic/FloorPlan.h>

#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace mrpt::opengl {
class COpenGLScene;
}

namespace slamdunk {

class SyntheticScene {
 public:
  /// Builds `plan`; `seed` selects the textures (the geometry is fixed, so every trajectory
  /// stays clear of the boxes whatever the seed). Each wall panel, floor, ceiling and box gets
  /// the next texture seed in that order, so a plan's images never change when another plan
  /// is edited.
  SyntheticScene(FloorPlan plan, unsigned seed, bool withCeiling = true);
  /// The "room" scene.
  explicit SyntheticScene(unsigned seed = 1, bool withCeiling = true);
  ~SyntheticScene();
  SyntheticScene(const SyntheticScene&) = delete;
  SyntheticScene& operator=(const SyntheticScene&) = delete;

  /// The scene to render (mutable: the renderer sets the viewport camera).
  mrpt::opengl::COpenGLScene& scene() const { return *scene_; }
  const FloorPlan& plan() const { return plan_; }
  const std::vector<RoomBox>& boxes() const { return plan_.boxes; }

  /// Rich, non-repetitive procedural texture (8-bit BGR), a pure function of its arguments.
  /// `detail` scales how many shapes are drawn on its smooth background (1: all of them; 0: a
  /// plain painted surface with its fine grain).
  static cv::Mat makeTexture(int width, int height, uint64_t seed, double detail = 1.0);

 private:
  FloorPlan plan_;
  std::shared_ptr<mrpt::opengl::COpenGLScene> scene_;
};

}  // namespace slamdunk
