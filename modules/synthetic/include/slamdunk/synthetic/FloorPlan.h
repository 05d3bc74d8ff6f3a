#pragma once
// Geometry of the synthetic environments, without any rendering: where the floor is, which walls
// close it, where the boxes stand. SyntheticScene textures and renders a floor plan; trajectories
// and tests use it to keep the camera in the free space.
//
// World frame: gravity aligned like a level optical frame, y points DOWN; the floor is the plane
// y = floorY and the ground-parallel coordinates are x and z. Every wall is vertical and spans
// the floor to the ceiling.

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace slamdunk {

/// Extents of the single room of the "room" scene in the world frame (metres).
struct RoomLayout {
  double xMin = -3.5, xMax = 3.5;
  double zMin = -3.0, zMax = 3.0;
  double floorY = 1.3;     ///< the world origin is at a hand-held camera's height above the floor
  double ceilingY = -1.4;  ///< 2.7 m high room
};

/// The "office" scene: four rooms at the corners of a rectangle, joined by corridors into a ring
/// (room A at the origin, then B along +x, C, D along +z). Rooms are as large as the "room"
/// scene's; the corridors run along the lines between room centres. The boxes are placed for
/// these dimensions.
struct OfficeLayout {
  double roomSizeX = 7.0, roomSizeZ = 6.0;
  double spacingX = 16.0, spacingZ = 13.0;  ///< between room centres (A to B, B to C)
  double corridorWidth = 2.4;
  double floorY = 1.3, ceilingY = -1.4;

  /// Centres of rooms A, B, C, D in ring order (x, z).
  std::array<Eigen::Vector2d, 4> roomCentres() const;
};

/// A walkable rectangle of floor (a room or a corridor), with a ceiling above it.
struct FloorArea {
  std::string name;
  double xMin = 0, xMax = 0, zMin = 0, zMax = 0;
  /// Share of the usual texture detail on its floor and ceiling (1: all; see
  /// SyntheticScene::makeTexture).
  double textureDetail = 1.0;
};

/// A vertical wall from the floor to the ceiling above the segment (x0, z0) -> (x1, z1), which
/// runs left to right as seen from the free space (the wall faces the viewer).
struct WallPanel {
  double x0 = 0, z0 = 0, x1 = 0, z1 = 0;
  /// Index in the plan's walls of a panel of the same length whose texture this one repeats
  /// (a repeated structure); -1: its own texture.
  int textureOf = -1;
  double textureDetail = 1.0;  ///< as FloorArea's
  double length() const;
};

/// A box resting on the floor or on another box.
struct RoomBox {
  double x = 0, z = 0;                           ///< centre of the footprint
  double sizeX = 0.5, sizeY = 0.5, sizeZ = 0.5;  ///< sizeY is the height
  double yawDeg = 0;                             ///< rotation about the vertical axis
  double baseY = 1.3;  ///< y of the bottom face (floorY when on the floor)
  /// Index in the plan's boxes of a box whose texture this one repeats; -1: its own texture.
  int textureOf = -1;
};

struct FloorPlan {
  std::string name;
  double floorY = 1.3, ceilingY = -1.4;
  /// The free space is the union of these rectangles; they may share edges but never overlap
  /// (each one gets its own floor and ceiling surface).
  std::vector<FloorArea> areas;
  /// The boundary of the free space: closed, nothing of the void shows between walls.
  std::vector<WallPanel> walls;
  std::vector<RoomBox> boxes;

  /// "room": one 7 x 6 m room with boxes along its walls (the sweep and loop trajectories).
  static FloorPlan room();
  /// "office": OfficeLayout's four rooms and corridors in a ring (245 m² of floor, 149 m of
  /// walls), boxes in every room and corridor (the tour trajectory).
  static FloorPlan office();
  /// "office" with room C built as a copy of room A turned half a turn about the office's
  /// centre (the ring is symmetric under that turn): C's walls and boxes stand where A's do
  /// seen from C, with A's textures. The tour sees the same views in A and in C: two identical
  /// rooms 20 m apart, for testing that they are not taken for one place.
  static FloorPlan officeWithTwinRooms();
  /// The same plan with the named area's floor, ceiling and walls (the panels on its boundary)
  /// painted almost plain: `detail` of the usual texture's shapes (its boxes keep theirs). A
  /// stretch where a camera finds few features. Throws std::invalid_argument for an unknown
  /// area.
  static FloorPlan withBareArea(FloorPlan plan, const std::string& area, double detail);
  static std::vector<std::string> names();
  /// Throws std::invalid_argument for an unknown name.
  static FloorPlan named(const std::string& name);

  /// True when (x, z) lies on the floor of some area (edges included).
  bool contains(double x, double z) const;
  /// How far (x, z) is from the nearest wall or box footprint (metres); negative outside the
  /// free space or inside a box. A camera whose clearance is c never has a surface nearer
  /// than c in any direction.
  double clearance(double x, double z) const;
};

/// The walls enclosing the union of `areas` (which must not overlap): the boundary of the
/// union, one panel per straight run, oriented as WallPanel says. Throws
/// std::invalid_argument when two areas overlap or an area is empty.
std::vector<WallPanel> wallsAround(const std::vector<FloorArea>& areas);

}  // namespace slamdunk
