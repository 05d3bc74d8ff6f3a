#include <slamdunk/core/DepthBackProjection.h>
#include <slamdunk/grid_map/FloorPlane.h>
#include <slamdunk/grid_map/GridMapBuilder.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace slamdunk {

namespace {

/// The obstacle band is cut into slices this high: a ray that passes over a table top at
/// 1 m must not clear the table seen at 0.75 m in the same cell.
constexpr double kSliceHeight = 0.05;
/// A ray that ends on a surface seen at a grazing angle (a table top from across the room)
/// runs just above it for a while: within this far of its end and this close to its end's
/// height, it clears nothing, or it would erode the surface it ends on.
constexpr double kEndMargin = 0.5, kEndLayer = 0.1;
/// OctoMap's default sensor model in log-odds: a hit +0.85 (p 0.7), a miss -0.41 (p 0.4).
constexpr double kHitLogOdds = 0.85, kMissLogOdds = 0.41;
constexpr int kMinHits = 2;  ///< a single stray reading does not make an obstacle
/// The camera's carrier (a robot, a person) passed between consecutive keyframes: the floor
/// this close to the segment joining them is free, where the camera itself hardly looks. Not
/// across a jump (a relocalization, a new map component).
constexpr double kFootprintRadius = 0.15, kMaxKeyframeStep = 2.0;

/// Visits the cells the segment (x0, y0) -> (x1, y1) crosses (cell units), in order, with the
/// segment's parameter in [0, 1] at the middle of its run through each; the last cell only when
/// `includeEnd`. Amanatides and Woo's traversal.
template <class Visit>
void traverseCells(double x0, double y0, double x1, double y1, bool includeEnd, Visit&& visit) {
  int ix = int(std::floor(x0)), iy = int(std::floor(y0));
  const int ex = int(std::floor(x1)), ey = int(std::floor(y1));
  const double dx = x1 - x0, dy = y1 - y0;
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  constexpr double inf = std::numeric_limits<double>::infinity();
  double tMaxX = dx != 0 ? (sx > 0 ? ix + 1 - x0 : x0 - ix) / std::abs(dx) : inf;
  double tMaxY = dy != 0 ? (sy > 0 ? iy + 1 - y0 : y0 - iy) / std::abs(dy) : inf;
  const double tDeltaX = dx != 0 ? 1 / std::abs(dx) : inf;
  const double tDeltaY = dy != 0 ? 1 / std::abs(dy) : inf;
  double tEntry = 0;
  for (int steps = std::abs(ex - ix) + std::abs(ey - iy); steps > 0; --steps) {
    const double tExit = std::min({tMaxX, tMaxY, 1.0});
    visit(ix, iy, 0.5 * (tEntry + tExit));
    tEntry = tExit;
    if (tMaxX < tMaxY)
      ix += sx, tMaxX += tDeltaX;
    else
      iy += sy, tMaxY += tDeltaY;
  }
  if (includeEnd) visit(ex, ey, 0.5 * (tEntry + 1));
}

/// Evidence per cell: hits and misses in each height slice of the obstacle band, and whether a
/// ray reached the floor's level there.
class Evidence {
 public:
  Evidence(int sizeX, int sizeY, int slices)
      : sizeX_(sizeX),
        slices_(slices),
        hits_(size_t(sizeX) * size_t(sizeY) * size_t(slices), 0),
        misses_(hits_.size(), 0),
        floorSeen_(size_t(sizeX) * size_t(sizeY), 0) {}

  void hit(int x, int y, int slice) { bump(hits_[index(x, y, slice)]); }
  void miss(int x, int y, int slice) { bump(misses_[index(x, y, slice)]); }
  void floor(int x, int y) { floorSeen_[size_t(y) * size_t(sizeX_) + size_t(x)] = 1; }

  /// Readings ended in slices where they outweigh the rays through them: at least kMinHits.
  bool occupied(int x, int y) const {
    int hits = 0;
    for (int s = 0; s < slices_; ++s) {
      const size_t i = index(x, y, s);
      if (kHitLogOdds * hits_[i] > kMissLogOdds * misses_[i]) hits += hits_[i];
    }
    return hits >= kMinHits;
  }
  bool seenFree(int x, int y) const {
    if (floorSeen_[size_t(y) * size_t(sizeX_) + size_t(x)]) return true;
    for (int s = 0; s < slices_; ++s)
      if (misses_[index(x, y, s)]) return true;
    return false;
  }

 private:
  static void bump(uint8_t& c) { c += c < 0xff; }
  size_t index(int x, int y, int slice) const {
    return (size_t(y) * size_t(sizeX_) + size_t(x)) * size_t(slices_) + size_t(slice);
  }
  int sizeX_, slices_;
  std::vector<uint8_t> hits_, misses_;
  std::vector<uint8_t> floorSeen_;
};

}  // namespace

/// The keyframes' depth readings in the map's world, with the camera each came from.
struct GridMapBuilder::Views {
  std::vector<Eigen::Vector3f> points;
  std::vector<Pose> cameras;
  std::vector<size_t> firstPoint;  ///< of each camera's points; one past the end last

  Views(const KeyframeGraph& graph, const GridMapOptions& o) {
    for (const auto& [id, pose] : graph.poses()) {
      const KeyframePtr kf = graph.keyframe(id);
      if (!kf || kf->depthSmall.empty()) continue;
      cv::Mat depth;
      kf->depthSmall.convertTo(depth, CV_32F);
      firstPoint.push_back(points.size());
      cameras.push_back(pose);
      const Eigen::Matrix3f R = pose.linear().cast<float>();
      const Eigen::Vector3f t = pose.translation().cast<float>();
      forEachDepthPoint(
          depth, kf->intrinsics, DepthSampling{o.pixelStride, kf->depthSmallStride, true},
          [&](float z) { return std::isfinite(z) && z > 0.1f && z <= o.maxDepth; },
          [&](int, int, const Eigen::Vector3d& p) { points.push_back(R * p.cast<float>() + t); });
    }
    firstPoint.push_back(points.size());
  }
};

GridMapBuilder::GridMapBuilder(GridMapOptions options) : options_(std::move(options)) {
  options_.validate();
}

Pose GridMapBuilder::floorUnderCamera(const Pose& T_world_camera,
                                      const mrpt::poses::CPose3D& sensorPose) {
  const Pose T_robot_camera = sensorToOpticalPose(fromCPose3D(sensorPose));
  return T_world_camera * T_robot_camera.inverse();
}

GridMap GridMapBuilder::build(const KeyframeGraph& graph,
                              const std::optional<mrpt::poses::CPose3D>& sensorPose) const {
  const Views views(graph, options_);
  if (views.cameras.empty())
    throw std::runtime_error("occupancy grid: no keyframe of the map kept its depth");
  const bool mounted = sensorPose && !(*sensorPose == mrpt::poses::CPose3D());
  if (options_.floor == GridFloor::SensorPose && !mounted)
    throw std::runtime_error(
        "occupancy grid: [grid_map] floor = sensor_pose, but the observations carry no pose of "
        "the camera on the robot (CObservation3DRangeScan::sensorPose is the identity)");
  if (mounted && options_.floor != GridFloor::Map)
    return rasterize(views, floorUnderCamera(views.cameras.front(), *sensorPose));
  const auto floor = findFloor(views.points, views.cameras);
  if (!floor)
    throw std::runtime_error(
        "occupancy grid: no floor found in the map's depth (no horizontal plane below the "
        "cameras holds enough points; did the camera look at the floor?)");
  return rasterize(views, floor->T_world_floor);
}

GridMap GridMapBuilder::buildOnFloor(const KeyframeGraph& graph, const Pose& T_world_floor) const {
  const Views views(graph, options_);
  if (views.cameras.empty())
    throw std::runtime_error("occupancy grid: no keyframe of the map kept its depth");
  return rasterize(views, T_world_floor);
}

GridMap GridMapBuilder::rasterize(const Views& views, const Pose& T_world_floor) const {
  const GridMapOptions& o = options_;
  const Pose T_floor_world = T_world_floor.inverse();
  const Eigen::Matrix3f R = T_floor_world.linear().cast<float>();
  const Eigen::Vector3f t = T_floor_world.translation().cast<float>();
  const float floorTolerance = float(o.minObstacleHeight);  // readings this far below: noise

  // Points in the floor frame, and the extent of everything that will touch a cell.
  std::vector<Eigen::Vector3f> points(views.points.size());
  Eigen::Vector2f lo(std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
  Eigen::Vector2f hi = -lo;
  const auto extend = [&](const Eigen::Vector3f& p) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  };
  for (size_t i = 0; i < points.size(); ++i) {
    points[i] = R * views.points[i] + t;
    if (points[i].z() >= -floorTolerance && points[i].z() <= o.maxObstacleHeight) extend(points[i]);
  }
  std::vector<Eigen::Vector3f> centres;
  for (const Pose& T : views.cameras) {
    centres.push_back((T_floor_world * T).translation().cast<float>());
    extend(centres.back());
  }

  GridMap out;
  out.T_world_floor = T_world_floor;
  out.keyframes = views.cameras.size();
  const float res = float(o.resolution), margin = 2 * res;
  const float xMin = std::floor((lo.x() - margin) / res) * res;
  const float yMin = std::floor((lo.y() - margin) / res) * res;
  const int sizeX = int(std::ceil((hi.x() + margin - xMin) / res));
  const int sizeY = int(std::ceil((hi.y() + margin - yMin) / res));
  out.grid.setSize(xMin, xMin + sizeX * res, yMin, yMin + sizeY * res, res, 0.5f);
  const int nx = int(out.grid.getSizeX()), ny = int(out.grid.getSizeY());

  const double bandLow = o.minObstacleHeight, bandHigh = o.maxObstacleHeight;
  const int slices = std::max(1, int(std::ceil((bandHigh - bandLow) / kSliceHeight)));
  const auto sliceOf = [&](double h) {
    return std::clamp(int((h - bandLow) / kSliceHeight), 0, slices - 1);
  };
  Evidence evidence(nx, ny, slices);
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < nx && y < ny; };

  for (size_t k = 0; k < views.cameras.size(); ++k) {
    const Eigen::Vector3f& c = centres[k];
    const double cx = (c.x() - xMin) / res, cy = (c.y() - yMin) / res;
    for (size_t i = views.firstPoint[k]; i < views.firstPoint[k + 1]; ++i) {
      const Eigen::Vector3f& p = points[i];
      if (p.z() < -floorTolerance || p.z() > bandHigh) continue;
      const bool obstacle = p.z() >= bandLow;
      const double px = (p.x() - xMin) / res, py = (p.y() - yMin) / res;
      const double length = (p.head<2>() - c.head<2>()).norm();
      traverseCells(cx, cy, px, py, !obstacle, [&](int x, int y, double s) {
        if (!inside(x, y)) return;
        const double h = c.z() + s * (p.z() - c.z());
        if (h < bandLow)
          evidence.floor(x, y);
        else if (h <= bandHigh &&
                 ((1 - s) * length > kEndMargin || std::abs(h - p.z()) > kEndLayer))
          evidence.miss(x, y, sliceOf(h));
      });
      if (obstacle && inside(int(px), int(py))) evidence.hit(int(px), int(py), sliceOf(p.z()));
    }
  }

  for (size_t k = 0; k + 1 < centres.size(); ++k) {
    const Eigen::Vector2f a = centres[k].head<2>(), b = centres[k + 1].head<2>();
    if ((b - a).norm() > kMaxKeyframeStep) continue;
    const Eigen::Vector2f lo2 = a.cwiseMin(b).array() - float(kFootprintRadius);
    const Eigen::Vector2f hi2 = a.cwiseMax(b).array() + float(kFootprintRadius);
    for (int y = int((lo2.y() - yMin) / res); y <= int((hi2.y() - yMin) / res); ++y)
      for (int x = int((lo2.x() - xMin) / res); x <= int((hi2.x() - xMin) / res); ++x) {
        const Eigen::Vector2f cell(xMin + (x + 0.5f) * res, yMin + (y + 0.5f) * res);
        const Eigen::Vector2f ab = b - a;
        const float s = ab.squaredNorm() > 0
                            ? std::clamp((cell - a).dot(ab) / ab.squaredNorm(), 0.f, 1.f)
                            : 0.f;
        if (inside(x, y) && (a + s * ab - cell).norm() <= kFootprintRadius) evidence.floor(x, y);
      }
  }

  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      if (evidence.occupied(x, y)) {
        out.grid.setCell(x, y, 0.0f);
        ++out.occupiedCells;
      } else if (evidence.seenFree(x, y)) {
        out.grid.setCell(x, y, 1.0f);
        ++out.freeCells;
      }
    }
  return out;
}

}  // namespace slamdunk
