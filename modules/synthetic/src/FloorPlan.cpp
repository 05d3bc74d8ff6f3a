#include <slamdunk/core/Pose.h>
#include <slamdunk/synthetic/FloorPlan.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace slamdunk {

namespace {

std::vector<RoomBox> roomBoxes(const RoomLayout& r) {
  // Fixed layout: against the walls, at least 0.9 m away from the camera paths of
  // SyntheticTrajectory (a 1 m circle around the room centre and the sweep near it).
  const double f = r.floorY;
  std::vector<RoomBox> b = {
      {r.xMax - 0.6, 1.6, 0.8, 0.9, 0.6, 10, f},  {r.xMax - 0.5, -0.8, 0.6, 0.5, 0.7, -15, f},
      {r.xMin + 0.5, 0.5, 0.7, 1.1, 0.6, 5, f},   {r.xMin + 0.6, -1.8, 0.9, 0.45, 0.6, 30, f},
      {0.8, r.zMax - 0.5, 1.2, 0.75, 0.5, 0, f},  {-1.1, r.zMax - 0.45, 0.5, 0.5, 0.5, 20, f},
      {0.3, r.zMin + 0.5, 0.8, 0.6, 0.6, -8, f},  {-1.4, r.zMin + 0.35, 0.4, 1.3, 0.4, 0, f},
      {1.9, r.zMin + 0.6, 0.5, 0.35, 0.5, 40, f}, {r.xMin + 0.6, 2.2, 0.6, 0.7, 0.6, -25, f},
  };
  // Smaller boxes standing on top of others.
  b.push_back({0.9, r.zMax - 0.5, 0.4, 0.3, 0.35, 25, f - 0.75});
  b.push_back({r.xMax - 0.6, 1.6, 0.35, 0.25, 0.3, -20, f - 0.9});
  return b;
}

/// Places boxes by their offset from `origin` (x, z): a room centre, or zero for world
/// coordinates. A box stands on the floor, or `heightAboveFloor` up when it sits on another.
struct BoxPlacer {
  Eigen::Vector2d origin;
  double floorY;
  RoomBox operator()(double dx, double dz, double sizeX, double sizeY, double sizeZ,
                     double yawDeg = 0, double heightAboveFloor = 0) const {
    RoomBox box;
    box.x = origin.x() + dx;
    box.z = origin.y() + dz;
    box.sizeX = sizeX;
    box.sizeY = sizeY;
    box.sizeZ = sizeZ;
    box.yawDeg = yawDeg;
    box.baseY = floorY - heightAboveFloor;
    return box;
  }
};

std::vector<RoomBox> officeBoxes(const OfficeLayout& o) {
  // The tour passes through each room on the lines between room centres and turns on a 2 m
  // arc inside it (SyntheticTrajectory "tour"). The camera looks to the right of its path,
  // towards the ring's outside: most clutter stands along the outer walls and in the outer
  // corner, a box in the open breaks up the floor, and the inner corner behind the arc holds
  // one more box. In the corridors, cabinets along the walls leave 0.8 m to the path.
  const auto c = o.roomCentres();
  const double f = o.floorY;
  std::vector<RoomBox> b;
  auto add = [&](std::initializer_list<RoomBox> boxes) { b.insert(b.end(), boxes); };
  // Room A: outer walls -x and -z.
  const BoxPlacer inA{c[0], f};
  add({inA(-1.9, -2.6, 1.2, 0.75, 0.6), inA(-2.1, -2.6, 0.4, 0.3, 0.35, 20, 0.75),
       inA(0.6, -2.7, 0.7, 1.8, 0.45), inA(2.4, -2.45, 0.6, 0.5, 0.6, 20),
       inA(-3.0, 0.4, 0.7, 0.9, 0.8, -8), inA(-2.85, 2.1, 0.8, 0.45, 0.8, 30),
       inA(-1.4, -1.1, 0.5, 0.5, 0.5, 35), inA(2.6, 2.2, 0.8, 0.6, 0.6)});
  // Room B: outer walls +x and -z.
  const BoxPlacer inB{c[1], f};
  add({inB(3.1, -0.5, 0.5, 1.1, 1.6), inB(-1.5, -2.65, 0.9, 0.6, 0.5),
       inB(0.9, -2.6, 0.6, 1.4, 0.6, -12), inB(2.9, -2.4, 0.7, 0.8, 0.7, 45),
       inB(2.9, -2.4, 0.4, 0.35, 0.4, 10, 0.8), inB(3.05, 1.9, 0.6, 0.7, 0.9, 5),
       inB(1.3, -1.3, 0.5, 0.45, 0.5, -25), inB(-2.6, 2.2, 0.6, 0.9, 0.6, 15)});
  // Room C: outer walls +x and +z.
  const BoxPlacer inC{c[2], f};
  add({inC(-2.0, 2.6, 1.4, 0.8, 0.6), inC(-1.7, 2.6, 0.5, 0.4, 0.4, -15, 0.8),
       inC(0.7, 2.55, 0.6, 1.9, 0.7), inC(2.85, 2.4, 0.9, 0.6, 0.9),
       inC(3.0, 0.3, 0.7, 1.0, 1.0, -10), inC(3.1, -2.0, 0.5, 0.5, 0.8),
       inC(1.4, 1.2, 0.6, 0.6, 0.4, 30), inC(-2.7, -2.3, 0.7, 0.6, 0.6)});
  // Room D: outer walls -x and +z.
  const BoxPlacer inD{c[3], f};
  add({inD(-3.1, -1.5, 0.5, 1.7, 1.0), inD(-3.0, 1.0, 0.7, 0.7, 0.7, 12),
       inD(-1.2, 2.65, 1.0, 0.9, 0.5), inD(1.3, 2.5, 0.8, 0.5, 0.6, -20),
       inD(1.3, 2.5, 0.35, 0.3, 0.3, 10, 0.5), inD(-2.9, 2.4, 0.7, 1.3, 0.7),
       inD(-1.5, 1.3, 0.45, 0.4, 0.45, 40), inD(2.6, -2.3, 0.7, 0.8, 0.5)});
  // Corridors, positions in world coordinates: cabinets and shelves against the walls.
  const BoxPlacer corridor{Eigen::Vector2d::Zero(), f};
  add({corridor(6.0, -0.98, 1.2, 0.9, 0.35), corridor(10.0, -1.0, 0.5, 1.6, 0.3),
       corridor(8.0, 1.0, 0.6, 0.5, 0.3)});                                         // A-B
  add({corridor(16.98, 5.0, 0.35, 1.0, 1.0), corridor(17.0, 8.2, 0.3, 0.6, 0.7)});  // B-C
  add({corridor(10.5, 13.98, 1.0, 0.7, 0.35), corridor(7.2, 14.0, 0.6, 1.5, 0.3),
       corridor(5.0, 14.0, 0.4, 0.4, 0.3)});                                        // C-D
  add({corridor(-0.98, 7.5, 0.35, 0.8, 1.2), corridor(-1.0, 4.6, 0.3, 1.2, 0.6)});  // D-A
  return b;
}

double distanceToSegment(double x, double z, const WallPanel& w) {
  const Eigen::Vector2d p(x, z), a(w.x0, w.z0), b(w.x1, w.z1);
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

/// Signed distance from (x, z) to a box's footprint: negative inside.
double signedDistanceToBox(double x, double z, const RoomBox& box) {
  // Into the box frame: the box's yaw rotates its local x towards -z (as the optical frame's
  // yaw does: world = (c lx + s lz, -s lx + c lz)), so local = transpose applied.
  const double c = std::cos(box.yawDeg * kDeg), s = std::sin(box.yawDeg * kDeg);
  const double dx = x - box.x, dz = z - box.z;
  const double lx = c * dx - s * dz, lz = s * dx + c * dz;
  const double qx = std::abs(lx) - box.sizeX / 2, qz = std::abs(lz) - box.sizeZ / 2;
  const double outside = std::hypot(std::max(qx, 0.0), std::max(qz, 0.0));
  const double inside = std::min(std::max(qx, qz), 0.0);
  return outside + inside;
}

/// Sorted distinct values; values closer than 1 nm are one (shared edges computed two ways).
std::vector<double> distinctSorted(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  std::vector<double> out;
  for (double x : v)
    if (out.empty() || x - out.back() > 1e-9) out.push_back(x);
  return out;
}

}  // namespace

std::array<Eigen::Vector2d, 4> OfficeLayout::roomCentres() const {
  return {Eigen::Vector2d(0, 0), Eigen::Vector2d(spacingX, 0), Eigen::Vector2d(spacingX, spacingZ),
          Eigen::Vector2d(0, spacingZ)};
}

double WallPanel::length() const { return std::hypot(x1 - x0, z1 - z0); }

FloorPlan FloorPlan::room() {
  const RoomLayout r;
  FloorPlan plan;
  plan.name = "room";
  plan.floorY = r.floorY;
  plan.ceilingY = r.ceilingY;
  plan.areas = {{"room", r.xMin, r.xMax, r.zMin, r.zMax}};
  // Listed rather than derived with wallsAround(): each wall's texture seed follows from its
  // place in this list, and the room's images predate the office.
  plan.walls = {
      {r.xMin, r.zMax, r.xMax, r.zMax},  // far wall (+z), seen looking along +z
      {r.xMax, r.zMin, r.xMin, r.zMin},  // near wall (-z)
      {r.xMax, r.zMax, r.xMax, r.zMin},  // +x wall
      {r.xMin, r.zMin, r.xMin, r.zMax},  // -x wall
  };
  plan.boxes = roomBoxes(r);
  return plan;
}

FloorPlan FloorPlan::office() {
  const OfficeLayout o;
  const auto c = o.roomCentres();
  const double hx = o.roomSizeX / 2, hz = o.roomSizeZ / 2, hw = o.corridorWidth / 2;
  FloorPlan plan;
  plan.name = "office";
  plan.floorY = o.floorY;
  plan.ceilingY = o.ceilingY;
  const char* roomNames[4] = {"room A", "room B", "room C", "room D"};
  for (int i = 0; i < 4; ++i)
    plan.areas.push_back(
        {roomNames[i], c[i].x() - hx, c[i].x() + hx, c[i].y() - hz, c[i].y() + hz});
  // Corridors fill the gaps between facing room walls (same expressions, so shared edges
  // are the same numbers), centred on the line between the room centres.
  plan.areas.push_back(
      {"corridor A-B", c[0].x() + hx, c[1].x() - hx, c[0].y() - hw, c[0].y() + hw});
  plan.areas.push_back(
      {"corridor B-C", c[1].x() - hw, c[1].x() + hw, c[1].y() + hz, c[2].y() - hz});
  plan.areas.push_back(
      {"corridor C-D", c[3].x() + hx, c[2].x() - hx, c[3].y() - hw, c[3].y() + hw});
  plan.areas.push_back(
      {"corridor D-A", c[0].x() - hw, c[0].x() + hw, c[0].y() + hz, c[3].y() - hz});
  plan.walls = wallsAround(plan.areas);
  plan.boxes = officeBoxes(o);
  return plan;
}

FloorPlan FloorPlan::officeWithTwinRooms() {
  const OfficeLayout o;
  const auto c = o.roomCentres();
  const Eigen::Vector2d centre = (c[0] + c[2]) / 2;
  auto turned = [&](double x, double z) {
    return Eigen::Vector2d(2 * centre.x() - x, 2 * centre.y() - z);
  };
  FloorPlan plan = office();
  plan.name = "office with twin rooms";
  const FloorArea& a = plan.areas[0];
  const FloorArea& roomC = plan.areas[2];
  auto onBoundary = [](const WallPanel& w, const FloorArea& area) {
    const double x = (w.x0 + w.x1) / 2, z = (w.z0 + w.z1) / 2;
    const double e = 1e-9;
    const bool inside =
        x >= area.xMin - e && x <= area.xMax + e && z >= area.zMin - e && z <= area.zMax + e;
    return inside && (std::abs(x - area.xMin) < e || std::abs(x - area.xMax) < e ||
                      std::abs(z - area.zMin) < e || std::abs(z - area.zMax) < e);
  };
  // Each wall of C repeats the wall of A that the turn brings onto it: the turn keeps a panel's
  // direction as seen from the free space, so its texture runs the same way.
  for (WallPanel& w : plan.walls) {
    if (!onBoundary(w, roomC)) continue;
    for (size_t i = 0; i < plan.walls.size(); ++i) {
      const WallPanel& q = plan.walls[i];
      if (!onBoundary(q, a)) continue;
      if ((turned(q.x0, q.z0) - Eigen::Vector2d(w.x0, w.z0)).norm() < 1e-9 &&
          (turned(q.x1, q.z1) - Eigen::Vector2d(w.x1, w.z1)).norm() < 1e-9)
        w.textureOf = static_cast<int>(i);
    }
    if (w.textureOf < 0)
      throw std::logic_error("office with twin rooms: a wall of room C has no twin in room A");
  }
  // Room C's boxes are officeBoxes()' 16-23 and A's 0-7: C's become A's, turned.
  for (int i = 0; i < 8; ++i) {
    RoomBox box = plan.boxes[size_t(i)];
    const Eigen::Vector2d p = turned(box.x, box.z);
    box.x = p.x();
    box.z = p.y();
    box.yawDeg += 180;
    box.textureOf = i;
    plan.boxes[size_t(16 + i)] = box;
  }
  return plan;
}

FloorPlan FloorPlan::withBareArea(FloorPlan plan, const std::string& areaName, double detail) {
  const auto area = std::find_if(plan.areas.begin(), plan.areas.end(),
                                 [&](const FloorArea& a) { return a.name == areaName; });
  if (area == plan.areas.end())
    throw std::invalid_argument("no area '" + areaName + "' in the " + plan.name + " plan");
  area->textureDetail = detail;
  const double e = 1e-9;
  for (WallPanel& w : plan.walls) {
    // A panel on the area's boundary: both ends on it, on one of its four sides.
    const bool alongX = std::abs(w.z0 - w.z1) < e &&
                        (std::abs(w.z0 - area->zMin) < e || std::abs(w.z0 - area->zMax) < e) &&
                        std::min(w.x0, w.x1) >= area->xMin - e &&
                        std::max(w.x0, w.x1) <= area->xMax + e;
    const bool alongZ = std::abs(w.x0 - w.x1) < e &&
                        (std::abs(w.x0 - area->xMin) < e || std::abs(w.x0 - area->xMax) < e) &&
                        std::min(w.z0, w.z1) >= area->zMin - e &&
                        std::max(w.z0, w.z1) <= area->zMax + e;
    if (alongX || alongZ) w.textureDetail = detail;
  }
  plan.name += " with a bare " + areaName;
  return plan;
}

std::vector<std::string> FloorPlan::names() { return {"room", "office"}; }

FloorPlan FloorPlan::named(const std::string& name) {
  if (name == "room") return room();
  if (name == "office") return office();
  throw std::invalid_argument("unknown synthetic scene '" + name + "' (known: room, office)");
}

bool FloorPlan::contains(double x, double z) const {
  return std::any_of(areas.begin(), areas.end(), [&](const FloorArea& a) {
    return x >= a.xMin && x <= a.xMax && z >= a.zMin && z <= a.zMax;
  });
}

double FloorPlan::clearance(double x, double z) const {
  double toWall = std::numeric_limits<double>::infinity();
  for (const auto& w : walls) toWall = std::min(toWall, distanceToSegment(x, z, w));
  double d = contains(x, z) ? toWall : -toWall;
  for (const auto& b : boxes) d = std::min(d, signedDistanceToBox(x, z, b));
  return d;
}

std::vector<WallPanel> wallsAround(const std::vector<FloorArea>& areas) {
  for (size_t i = 0; i < areas.size(); ++i) {
    const auto& a = areas[i];
    if (!(a.xMax > a.xMin && a.zMax > a.zMin))
      throw std::invalid_argument("floor area '" + a.name + "' is empty");
    for (size_t j = 0; j < i; ++j) {
      const auto& b = areas[j];
      const double ox = std::min(a.xMax, b.xMax) - std::max(a.xMin, b.xMin);
      const double oz = std::min(a.zMax, b.zMax) - std::max(a.zMin, b.zMin);
      if (ox > 1e-9 && oz > 1e-9)
        throw std::invalid_argument("floor areas '" + a.name + "' and '" + b.name + "' overlap");
    }
  }
  // Cut the plane along every area edge: each cell of that grid is wholly free or wholly
  // solid, and the boundary of the free space runs along cell edges where free meets solid.
  std::vector<double> xs, zs;
  for (const auto& a : areas) {
    xs.insert(xs.end(), {a.xMin, a.xMax});
    zs.insert(zs.end(), {a.zMin, a.zMax});
  }
  xs = distinctSorted(xs);
  zs = distinctSorted(zs);
  const int nx = int(xs.size()) - 1, nz = int(zs.size()) - 1;
  auto isFree = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= nx || j >= nz) return false;
    const double x = (xs[i] + xs[i + 1]) / 2, z = (zs[j] + zs[j + 1]) / 2;
    return std::any_of(areas.begin(), areas.end(), [&](const FloorArea& a) {
      return x > a.xMin && x < a.xMax && z > a.zMin && z < a.zMax;
    });
  };

  // Along each grid line, consecutive boundary edges facing the same way make one wall. A wall
  // runs left to right as seen from the free side: with n pointing from the free side into the
  // solid one, "right" is (n.z, -n.x) (yaw convention: looking along +z, right is +x).
  std::vector<WallPanel> walls;
  auto emitRuns = [&](int cells, auto boundaryAt, auto makeWall) {
    int runStart = -1, runSide = 0;
    for (int k = 0; k <= cells; ++k) {
      const int side = k < cells ? boundaryAt(k) : 0;  // 0: no wall, +1/-1: which way it faces
      if (side != runSide) {
        if (runSide != 0) walls.push_back(makeWall(runStart, k, runSide));
        runStart = k;
        runSide = side;
      }
    }
  };
  for (int i = 0; i <= nx; ++i) {  // walls along z at x = xs[i]
    emitRuns(
        nz,
        [&](int j) {
          const bool left = isFree(i - 1, j), right = isFree(i, j);
          return left == right ? 0 : (left ? +1 : -1);  // +1: solid towards +x
        },
        [&](int j0, int j1, int side) {
          const double x = xs[i];
          return side > 0 ? WallPanel{x, zs[j1], x, zs[j0]} : WallPanel{x, zs[j0], x, zs[j1]};
        });
  }
  for (int j = 0; j <= nz; ++j) {  // walls along x at z = zs[j]
    emitRuns(
        nx,
        [&](int i) {
          const bool below = isFree(i, j - 1), above = isFree(i, j);
          return below == above ? 0 : (below ? +1 : -1);  // +1: solid towards +z
        },
        [&](int i0, int i1, int side) {
          const double z = zs[j];
          return side > 0 ? WallPanel{xs[i0], z, xs[i1], z} : WallPanel{xs[i1], z, xs[i0], z};
        });
  }
  return walls;
}

}  // namespace slamdunk
