#pragma once
// A textured indoor room (floor, four walls, optional ceiling, boxes) for synthetic RGB-D
// sequences. Every surface carries its own procedural texture, generated deterministically from
// a seed: dense, high-contrast detail at several scales and never repeated, so feature detectors
// find many distinctive keypoints everywhere and matches are never ambiguous.
//
// World frame: gravity aligned like a level optical frame, y points DOWN; the floor is the plane
// y = floorY and the ground-parallel coordinates are x and z.

#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace mrpt::opengl {
class COpenGLScene;
}

namespace slamdunk {

/// Extents of the synthetic room in the world frame (metres).
struct RoomLayout {
  double xMin = -3.5, xMax = 3.5;
  double zMin = -3.0, zMax = 3.0;
  double floorY = 1.3;     ///< the world origin is at a hand-held camera's height above the floor
  double ceilingY = -1.4;  ///< 2.7 m high room
};

/// A box resting on the floor or on another box.
struct RoomBox {
  double x = 0, z = 0;                           ///< centre of the footprint
  double sizeX = 0.5, sizeY = 0.5, sizeZ = 0.5;  ///< sizeY is the height
  double yawDeg = 0;                             ///< rotation about the vertical axis
  double baseY = 1.3;  ///< y of the bottom face (floorY when on the floor)
};

class SyntheticScene {
 public:
  /// Builds the room; `seed` selects the textures (the geometry is fixed, so every trajectory
  /// stays clear of the boxes whatever the seed).
  explicit SyntheticScene(unsigned seed = 1, bool withCeiling = true);
  ~SyntheticScene();
  SyntheticScene(const SyntheticScene&) = delete;
  SyntheticScene& operator=(const SyntheticScene&) = delete;

  /// The scene to render (mutable: the renderer sets the viewport camera).
  mrpt::opengl::COpenGLScene& scene() const { return *scene_; }
  const RoomLayout& layout() const { return layout_; }
  const std::vector<RoomBox>& boxes() const { return boxes_; }

  /// Rich, non-repetitive procedural texture (8-bit BGR), a pure function of its arguments.
  static cv::Mat makeTexture(int width, int height, uint64_t seed);

 private:
  RoomLayout layout_;
  std::vector<RoomBox> boxes_;
  std::shared_ptr<mrpt::opengl::COpenGLScene> scene_;
};

}  // namespace slamdunk
