#include <slamdunk/grid_map/FloorPlane.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace slamdunk {

namespace {

constexpr size_t kMaxSampledPoints = 60000;
constexpr int kRansacIterations = 400;
constexpr double kMaxTiltFromCamerasDeg = 35;
constexpr double kInlierDistance = 0.03;       // metres from the plane
constexpr double kMinDropBelowCameras = 0.2;   // metres: the floor is below the camera
constexpr double kHistogramBin = 0.02;         // metres
constexpr double kFloorShareOfBestBin = 0.15;  // of the fullest horizontal bin's points
constexpr size_t kMinSupport = 200;

struct Plane {
  Eigen::Vector3d normal;  ///< unit, pointing up
  double offset = 0;       ///< normal . p = offset on the plane
  double height(const Eigen::Vector3d& p) const { return normal.dot(p) - offset; }
};

std::vector<Eigen::Vector3d> thinned(const std::vector<Eigen::Vector3f>& points) {
  const size_t step = std::max<size_t>(1, points.size() / kMaxSampledPoints);
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size() / step + 1);
  for (size_t i = 0; i < points.size(); i += step) out.push_back(points[i].cast<double>());
  return out;
}

double medianOf(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// The median height of the camera centres above the plane.
double cameraHeight(const Plane& plane, const std::vector<Pose>& cameras) {
  std::vector<double> h;
  for (const Pose& T : cameras) h.push_back(plane.height(T.translation()));
  return medianOf(h);
}

size_t countWithin(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tol) {
  size_t n = 0;
  for (const auto& p : points) n += std::abs(plane.height(p)) < tol;
  return n;
}

std::optional<Plane> bestHorizontalPlane(const std::vector<Eigen::Vector3d>& points,
                                         const std::vector<Pose>& cameras,
                                         const Eigen::Vector3d& up) {
  std::mt19937 rng(47);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  const double minCos = std::cos(kMaxTiltFromCamerasDeg * M_PI / 180);
  std::optional<Plane> best;
  size_t bestCount = 0;
  for (int it = 0; it < kRansacIterations; ++it) {
    const Eigen::Vector3d& a = points[pick(rng)];
    const Eigen::Vector3d& b = points[pick(rng)];
    const Eigen::Vector3d& c = points[pick(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-6) continue;
    n.normalize();
    if (n.dot(up) < 0) n = -n;
    if (n.dot(up) < minCos) continue;
    const Plane plane{n, n.dot(a)};
    if (cameraHeight(plane, cameras) < kMinDropBelowCameras) continue;
    const size_t count = countWithin(plane, points, kInlierDistance);
    if (count > bestCount) best = plane, bestCount = count;
  }
  return best;
}

/// Least-squares plane through the points within `tol` of `plane`, normal still up.
Plane refit(const Plane& plane, const std::vector<Eigen::Vector3d>& points, double tol) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  size_t n = 0;
  for (const auto& p : points)
    if (std::abs(plane.height(p)) < tol) mean += p, ++n;
  if (n < 3) return plane;
  mean /= double(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points)
    if (std::abs(plane.height(p)) < tol) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d normal = eig.eigenvectors().col(0);  // smallest eigenvalue
  if (normal.dot(plane.normal) < 0) normal = -normal;
  return {normal, normal.dot(mean)};
}

/// The lowest plane parallel to `reference`, below the cameras, that holds a fair share of the
/// points: the floor under a table top.
std::optional<Plane> lowestParallelPlane(const Plane& reference,
                                         const std::vector<Eigen::Vector3d>& points,
                                         const std::vector<Pose>& cameras) {
  const double top = cameraHeight(reference, cameras) - kMinDropBelowCameras;
  double lo = top;
  for (const auto& p : points) lo = std::min(lo, reference.height(p));
  const int bins = int((top - lo) / kHistogramBin) + 1;
  if (bins < 1 || bins > 100000) return std::nullopt;
  std::vector<size_t> histogram(size_t(bins), 0);
  for (const auto& p : points) {
    const double h = reference.height(p);
    if (h < top) ++histogram[size_t(std::min(bins - 1, int((h - lo) / kHistogramBin)))];
  }
  const size_t fullest = *std::max_element(histogram.begin(), histogram.end());
  for (int b = 0; b < bins; ++b) {
    if (histogram[size_t(b)] < std::max(kMinSupport / 4, size_t(kFloorShareOfBestBin * fullest)))
      continue;
    const double h = lo + (b + 0.5) * kHistogramBin;
    return Plane{reference.normal, reference.offset + h};
  }
  return std::nullopt;
}

}  // namespace

std::optional<FloorFrame> findFloor(const std::vector<Eigen::Vector3f>& worldPoints,
                                    const std::vector<Pose>& T_world_cameras) {
  if (worldPoints.size() < kMinSupport || T_world_cameras.empty()) return std::nullopt;
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const Pose& T : T_world_cameras) up -= T.linear().col(1);  // optical y points down
  if (up.norm() < 1e-3 * double(T_world_cameras.size())) return std::nullopt;
  up.normalize();

  const std::vector<Eigen::Vector3d> points = thinned(worldPoints);
  const auto horizontal = bestHorizontalPlane(points, T_world_cameras, up);
  if (!horizontal) return std::nullopt;
  const Plane reference = refit(*horizontal, points, kInlierDistance);
  auto lowest = lowestParallelPlane(reference, points, T_world_cameras);
  if (!lowest) return std::nullopt;
  Plane floor = refit(refit(*lowest, points, 2.5 * kInlierDistance), points, kInlierDistance);
  if (floor.normal.dot(reference.normal) < std::cos(10 * M_PI / 180)) floor = *lowest;
  const size_t support = countWithin(floor, points, kInlierDistance);
  if (support < kMinSupport || cameraHeight(floor, T_world_cameras) < kMinDropBelowCameras)
    return std::nullopt;

  const Pose& first = T_world_cameras.front();
  const Eigen::Vector3d z = floor.normal;
  Eigen::Vector3d x = first.linear().col(2) - first.linear().col(2).dot(z) * z;
  if (x.norm() < 0.1) x = first.linear().col(0) - first.linear().col(0).dot(z) * z;
  x.normalize();
  FloorFrame frame;
  frame.T_world_floor.linear().col(0) = x;
  frame.T_world_floor.linear().col(1) = z.cross(x);
  frame.T_world_floor.linear().col(2) = z;
  frame.T_world_floor.translation() = first.translation() - floor.height(first.translation()) * z;
  frame.supportingPoints = support;
  return frame;
}

}  // namespace slamdunk
